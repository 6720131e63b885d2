"""moon_craters.py (tests/bench) places lon/lat on a global grid whatever longitude its left
edge is at: geographic grids from 180 W or 0 E, and an equirectangular one centred on 180 E
(LDEM_4's layout)."""

import sys

import numpy as np
from osgeo import gdal

from conftest import SOURCE_DIR

sys.path.insert(0, str(SOURCE_DIR / "tests" / "bench"))
import moon_craters  # noqa: E402

MOON_M = 1737400.0


def grid(tmp_path, name, crs, transform, w=360, h=180):
    path = str(tmp_path / name)
    ds = gdal.GetDriverByName("GTiff").Create(path, w, h, 1, gdal.GDT_UInt16)
    ds.SetProjection(crs)
    ds.SetGeoTransform(transform)
    ds = None
    return gdal.Open(path)


def test_grid_origin_reads_the_left_and_top_edges(tmp_path):
    west = grid(tmp_path, "west.tif", "IAU_2015:30100", (-180, 1, 0, 90, 0, -1))
    assert moon_craters.grid_origin(west) == (-180, 90)
    east = grid(tmp_path, "east.tif", "IAU_2015:30100", (0, 1, 0, 90, 0, -1))
    assert moon_craters.grid_origin(east) == (0, 90)
    # Equirectangular, longitude of origin 180 E, x from -pi R: the left edge is at 0 E.
    eqc = grid(tmp_path, "eqc.tif", f"+proj=eqc +lon_0=180 +R={MOON_M} +units=m +no_defs",
               (-np.pi * MOON_M, 2 * np.pi * MOON_M / 360, 0, np.pi * MOON_M / 2, 0,
                -np.pi * MOON_M / 180))
    lon, lat = moon_craters.grid_origin(eqc)
    assert abs(((lon + 180) % 360) - 180) < 1e-6 and abs(lat - 90) < 1e-6


def test_grid_position_wraps_longitudes():
    col, row = moon_craters.grid_position([-170, 10, 190], [45, 0, -45], (-180, 90), 360, 180)
    assert np.allclose(col, [10, 190, 10]) and np.allclose(row, [45, 90, 135])
    col, _ = moon_craters.grid_position([-170, 10], [0, 0], (0, 90), 360, 180)
    assert np.allclose(col, [190, 10])
