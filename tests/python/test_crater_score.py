"""The crater benchmarks' rule (tests/bench/crater_score.py) on label maps whose answer is
known, and the landform defaults against the generator's craters on a small tile."""

import csv
import json
import sys

import numpy as np
from osgeo import gdal

from conftest import SOURCE_DIR

sys.path.insert(0, str(SOURCE_DIR / "tests" / "bench"))
import crater_score  # noqa: E402

CONCAVE, PLANAR = 20.0, 50.0


def disk(shape, col, row, radius):
    yy, xx = np.indices(shape)
    return np.hypot(xx + 0.5 - col, yy + 0.5 - row) <= radius


def judged(rows):
    """(concave crater-sized regions that are craters, concave crater-sized regions) over
    the bins: a floor is binned by its own equivalent diameter, smaller than its crater's."""
    return sum(r["true"] for r in rows), sum(r["regions"] for r in rows)


def one_crater(col=50.0, row=50.0, diameter=20.0, **extra):
    table = {"col": [col], "row": [row], "diameter_px": [diameter], "degradation": [0.0]}
    table.update({k: [v] for k, v in extra.items()})
    return {k: np.array(v, float) for k, v in table.items()}


def test_a_concave_floor_within_the_rim_is_found():
    labels = np.ones((100, 100), np.int64)
    labels[disk(labels.shape, 50, 50, 9)] = 2
    rows = crater_score.score(labels, [np.nan, PLANAR, CONCAVE], one_crater())
    assert rows[1]["bin"] == "20-50" and rows[1]["found"] == 1 and rows[1]["craters"] == 1
    assert judged(rows) == (1, 1)


def test_a_floor_that_is_not_concave_spills_out_or_covers_too_little_is_missed():
    base = np.ones((100, 100), np.int64)
    floor = base.copy()
    floor[disk(base.shape, 50, 50, 9)] = 2
    # Convex on average (a central peak region), or saddle-like: not a floor.
    assert crater_score.score(floor, [np.nan, PLANAR, 60.0], one_crater())[1]["found"] == 0
    assert crater_score.score(floor, [np.nan, PLANAR, 45.0], one_crater())[1]["found"] == 0
    # The region holding the bowl reaches far beyond 1.3 R: less than 70 % near the crater.
    spill = base.copy()
    spill[disk(base.shape, 50, 50, 9)] = 2
    spill[:, 70:] = 2
    assert crater_score.score(spill, [np.nan, PLANAR, CONCAVE], one_crater())[1]["found"] == 0
    # The bowl split in four: the largest piece covers under 40 % of it.
    split = base.copy()
    inner = disk(base.shape, 50, 50, 9)
    yy, xx = np.indices(base.shape)
    split[inner] = 2 + (yy[inner] >= 50) * 2 + (xx[inner] >= 50)
    rows = crater_score.score(split, [np.nan, PLANAR] + [CONCAVE] * 4, one_crater())
    assert rows[1]["found"] == 0


def test_scored_craters_leave_out_the_degraded_the_cut_and_the_overprinted():
    craters = {"col": np.array([50.0, 5.0, 150.0, 150.0]),
               "row": np.array([50.0, 50.0, 50.0, 52.0]),
               "diameter_px": np.array([20.0, 20.0, 20.0, 30.0]),
               "degradation": np.array([0.7, 0.0, 0.0, 0.0])}
    # 0: too degraded; 1: cut by the edge; 2: overprinted by the younger 3; 3: scored.
    assert crater_score.scored(craters, 200, 100).tolist() == [3]


def test_a_concave_region_far_from_any_crater_is_a_false_one_and_edges_do_not_count():
    labels = np.ones((100, 100), np.int64)
    labels[disk(labels.shape, 50, 50, 9)] = 2
    labels[disk(labels.shape, 80, 20, 8)] = 3    # a low with no crater
    labels[disk(labels.shape, 0, 90, 12)] = 4    # at the edge: not judged
    rows = crater_score.score(labels, [np.nan, PLANAR, CONCAVE, CONCAVE, CONCAVE],
                              one_crater())
    assert judged(rows) == (1, 2)


def test_a_global_grid_wraps_at_the_seam_and_scales_columns_by_latitude():
    # A crater on the seam of a 400 x 200 global grid at latitude 0; its floor straddles it.
    labels = np.ones((200, 400), np.int64)
    yy, xx = np.indices(labels.shape)
    dx = np.minimum(xx + 0.5, 400 - (xx + 0.5))
    labels[np.hypot(dx, yy + 0.5 - 100) <= 9] = 2
    craters = one_crater(col=0.0, row=100.0, lat=0.0, col_scale=1.0)
    rows = crater_score.score(labels, [np.nan, PLANAR, CONCAVE], craters, wrap=True)
    assert rows[1]["found"] == 1 and judged(rows) == (1, 1)


def test_the_default_segmentation_finds_the_generated_craters(cli, tmp_path):
    # A 384-pixel synthetic tile: the landform defaults find most scored craters of 10 px
    # and more, and most concave crater-sized regions are craters; the paper's 0.5 % finds
    # almost none of them.
    dem, table = tmp_path / "t.lbl", tmp_path / "t.csv"
    done = cli("synth", "-o", dem, "--width", 384, "--height", 384, "--seed", 5, "--craters",
               table, "-q")
    assert done.returncode == 0, done.stderr
    with open(table) as f:
        rows = list(csv.DictReader(f))
    craters = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}

    def scores(*options):
        out = tmp_path / ("o" + "_".join(options))
        assert cli("segment", dem, "-o", out, "-q", *options).returncode == 0
        ds = gdal.Open(str(out / "labels.tif"))
        labels = ds.GetRasterBand(1).ReadAsArray().astype(np.int64)
        mean = np.full(int(labels.max()) + 1, np.nan)
        for feature in json.loads((out / "regions.geojson").read_text())["features"]:
            mean[feature["properties"]["id"]] = feature["properties"]["field_mean"]
        rows = crater_score.score(labels, mean, craters)
        found = sum(r["found"] for r in rows) / max(1, sum(r["craters"] for r in rows))
        true = sum(r["true"] for r in rows) / max(1, sum(r["regions"] for r in rows))
        return found, true, sum(r["craters"] for r in rows)

    found, true, scored = scores()
    assert scored >= 20
    assert found >= 0.8 and true >= 0.8
    paper_found, _, _ = scores("--area-ratio", "0.5", "--persistence", "10")
    assert paper_found < 0.5
