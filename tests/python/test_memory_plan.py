"""The memory plan (docs/robustness.md): the command line and the Python module check an
input's estimated peak memory against the same limit, and refuse it with the same line."""

import re

import pytest

import terrain
from conftest import SAMPLE_FILES

NEEDED = re.compile(r"needs about [^(]+\((\d+) bytes\) but the memory limit is [^(]+\((\d+) bytes\)$")


def needed_bytes(cli, command, path, out, *args):
    """The estimate the command line names when refusing under a limit of one byte."""
    done = cli(command, path, "-o", out, "-q", "--max-memory", "1", *args)
    assert done.returncode == 1, done.stderr
    line = done.stderr.strip()
    assert "\n" not in line
    match = NEEDED.search(line)
    assert match, line
    assert int(match.group(2)) == 1
    return int(match.group(1))


@pytest.mark.parametrize("field", ["shape-index", "height"])
def test_a_dem_just_over_the_limit_is_refused_alike_and_just_under_it_runs(cli, tmp_path, field):
    dem = str(SAMPLE_FILES["vesta"])
    needed = needed_bytes(cli, "segment", dem, tmp_path / "probe", "--field", field)
    # The estimate grows with the grid: at least the process and 100 bytes a pixel.
    assert needed > 256 * 1024 * 100

    below = needed - 1
    done = cli("segment", dem, "-o", tmp_path / "below", "-q", "--field", field,
               "--max-memory", below)
    assert done.returncode == 1
    assert not (tmp_path / "below").exists()
    with pytest.raises(terrain.Error) as refused:
        terrain.segment(dem, field=field, max_memory=below)
    assert done.stderr.strip() == "terrain segment: " + str(refused.value)
    assert f"({needed} bytes)" in str(refused.value)
    assert f"({below} bytes)" in str(refused.value)
    # The same limit as a size with a unit, and the same check in the other entry points.
    with pytest.raises(terrain.Error, match="memory limit is 1 MB"):
        terrain.shape_index(dem, max_memory="1M")
    with pytest.raises(terrain.Error, match="memory limit"):
        terrain.sweep(dem, field=field, max_memory=below)

    done = cli("segment", dem, "-o", tmp_path / "at", "-q", "--field", field,
               "--max-memory", needed)
    assert done.returncode == 0, done.stderr
    result = terrain.segment(dem, field=field, max_memory=needed)
    assert result.region_count > 1


def test_a_mesh_for_the_sdf_is_planned_alike(cli, tmp_path):
    mesh = tmp_path / "moon.ply"
    assert cli("mesh", SAMPLE_FILES["moon4c"], "-o", mesh, "-q").returncode == 0
    args = ("--field", "sdf", "--allow-open", "--rays", "5")
    needed = needed_bytes(cli, "segment", mesh, tmp_path / "probe", *args)
    shape_needed = needed_bytes(cli, "segment", mesh, tmp_path / "probe", "--field", "shape-index")
    assert needed > shape_needed  # the SDF's plan is the larger

    done = cli("segment", mesh, "-o", tmp_path / "below", "-q", *args, "--max-memory", needed - 1)
    assert done.returncode == 1
    with pytest.raises(terrain.Error) as refused:
        terrain.segment(str(mesh), field="sdf", allow_open=True, rays=5, max_memory=needed - 1)
    assert done.stderr.strip() == "terrain segment: " + str(refused.value)

    done = cli("segment", mesh, "-o", tmp_path / "at", "-q", *args, "--max-memory", needed)
    assert done.returncode == 0, done.stderr
    assert terrain.segment(str(mesh), field="sdf", allow_open=True, rays=5,
                           max_memory=needed).region_count >= 1


def test_bad_limits_are_refused(tmp_path):
    dem = str(SAMPLE_FILES["vesta"])
    for bad in ("lots", "-5G", 0):
        with pytest.raises(terrain.Error, match="not a memory size"):
            terrain.segment(dem, max_memory=bad)


def test_a_dem_mostly_nodata_is_planned_by_its_valid_pixels(cli, tmp_path):
    """The plan counts the grids by the declared pixels and the rest by the valid ones: a
    3000 x 3000 DEM (its grids past the plan's floor) with one valid 100 x 100 patch runs
    under a limit that planning every declared pixel as valid would refuse."""
    import numpy as np
    from osgeo import gdal

    path = str(tmp_path / "patch.tif")
    values = np.full((3000, 3000), -9999.0, dtype=np.float32)
    y, x = np.mgrid[0:100, 0:100]
    values[1200:1300, 1200:1300] = 0.05 * ((x - 50.0) ** 2 + (y - 40.0) ** 2) + 3 * np.sin(x / 7.0)
    ds = gdal.GetDriverByName("GTiff").Create(path, 3000, 3000, 1, gdal.GDT_Float32,
                                              ["COMPRESS=DEFLATE", "TILED=YES"])
    ds.SetGeoTransform([0, 10, 0, 0, 0, -10])
    band = ds.GetRasterBand(1)
    band.SetNoDataValue(-9999)
    band.WriteArray(values)
    ds = None

    # Before reading, only the grids are known: the refusal names them alone.
    first = needed_bytes(cli, "segment", path, tmp_path / "probe")
    done = cli("segment", path, "-o", tmp_path / "grids", "-q", "--max-memory", first)
    assert done.returncode == 1
    assert not (tmp_path / "grids").exists()
    line = done.stderr.strip()
    assert "\n" not in line
    assert "with 10000 valid pixels" in line, line
    second = int(NEEDED.search(line).group(1))
    # The valid pixels add their share: more than 50 bytes each, far less than the whole grid.
    assert second - first > 50 * 10000
    assert second - first < 50 * 3000 * 3000
    done = cli("segment", path, "-o", tmp_path / "run", "-q", "--max-memory", second)
    assert done.returncode == 0, done.stderr
    with pytest.raises(terrain.Error, match="with 10000 valid pixels"):
        terrain.segment(path, max_memory=second - 1)
    assert terrain.segment(path, max_memory=second).region_count >= 1
