"""The crater-table benchmark's rule (tests/bench/crater_table_score.py) on tables whose
answer is known, and the crater table of a synthetic tile against the generator's craters."""

import csv
import sys

import numpy as np
import pytest

from conftest import SOURCE_DIR

sys.path.insert(0, str(SOURCE_DIR / "tests" / "bench"))
import crater_table_score  # noqa: E402

PIXEL = 10.0  # metres


def truth(*craters):
    """Generated craters: (col, row, diameter_px, degradation)."""
    c = np.array(craters, float)
    return {"col": c[:, 0], "row": c[:, 1], "diameter_px": c[:, 2], "degradation": c[:, 3]}


def table(*craters):
    """Listed craters: (col, row, diameter_px)."""
    c = np.array(craters, float)
    return {"col": c[:, 0], "row": c[:, 1], "diameter_m": c[:, 2] * PIXEL}


def test_a_crater_is_found_within_half_a_radius_and_a_factor_of_one_and_a_half():
    t = truth((50, 50, 30, 0), (150, 50, 15, 0))
    cases = [
        (table((52, 51, 31), (150, 50, 15)), 2, 2),   # both found
        (table((59, 50, 30), (150, 50, 15)), 1, 1),   # 0.6 R off: the first missed, unmatched
        (table((50, 50, 46), (150, 50, 15)), 1, 1),   # 1.53 times too large
        (table((50, 50, 19), (150, 50, 15)), 1, 1),   # 1.58 times too small
    ]
    for listed, found, matched in cases:
        s = crater_table_score.score(listed, t, 200, 100, PIXEL)
        assert sum(b[0] for b in s["bins"].values()) == found
        assert sum(b[1] for b in s["bins"].values()) == 2
        assert sum(b[2] for b in s["bins"].values()) == matched
        assert sum(b[3] for b in s["bins"].values()) == 2
    s = crater_table_score.score(table((53, 50, 33), (150, 50, 15)), t, 200, 100, PIXEL)
    assert s["diameter_error"] == pytest.approx(0.05)  # median of 0.1 and 0
    assert s["centre_error"] == pytest.approx(0.1)     # 3 px of 15 and 0


def test_precision_counts_listed_craters_in_the_grid_against_fresh_craters():
    t = truth((50, 50, 30, 0.95), (150, 50, 15, 0.5))
    # The first generated crater is too degraded to be scored or matched; a listed crater
    # off the grid's edge is not counted.
    s = crater_table_score.score(table((50, 50, 30), (150, 50, 15), (195, 50, 20)), t, 200,
                                 100, PIXEL)
    assert sum(b[1] for b in s["bins"].values()) == 1
    assert sum(b[2] for b in s["bins"].values()) == 1
    assert sum(b[3] for b in s["bins"].values()) == 2


def test_the_crater_table_of_a_synthetic_tile_finds_the_generators_craters(cli, tmp_path):
    # A 512 x 512 synthetic Vesta tile with no options: most of its craters of 10 px and more
    # are listed, and most listed craters are generated ones.
    dem, craters = tmp_path / "tile.lbl", tmp_path / "craters.csv"
    assert cli("synth", "-o", dem, "--width", "512", "--height", "512", "--seed", "5",
               "--craters", craters, "-q").returncode == 0
    out = tmp_path / "seg"
    assert cli("segment", dem, "-o", out, "-q").returncode == 0

    def read(path, keys):
        with open(path) as f:
            rows = list(csv.DictReader(f))
        return {k: np.array([float(r[k]) for r in rows]) for k in keys}

    gen = read(craters, ("col", "row", "diameter_px", "degradation", "depth_m"))
    listed = read(out / "craters.csv", ("col", "row", "diameter_m", "depth_m"))
    from osgeo import gdal
    ds = gdal.Open(str(dem))
    s = crater_table_score.score(listed, gen, 512, 512, abs(ds.GetGeoTransform()[5]))
    found = sum(b[0] for b in s["bins"].values())
    scored = sum(b[1] for b in s["bins"].values())
    matched = sum(b[2] for b in s["bins"].values())
    counted = sum(b[3] for b in s["bins"].values())
    assert scored >= 20
    assert found >= 0.7 * scored  # (37 of 46 today)
    assert matched >= 0.8 * counted  # (52 of 58 today)
    assert s["diameter_error"] < 0.1 and s["centre_error"] < 0.2
    assert s["depth_error"] < 0.15
