"""Region polygons of global grids, read back through Debian's clients (GDAL/OGR, shapely,
geopandas, pyproj, rasterio): split at the grid's seam, valid, within +-90 degrees, pole caps
closed, areas on the body adding up to the body's, and rasterised back onto the grid they
give each region its pixels (what QGIS's zonal statistics do). docs/outputs.md, "Global
grids"."""

import json
import math

import pytest

MOON_RADIUS = 1737400.0


def global_moon_dem(path, west):
    """A 1-degree global grid of the Moon (IAU_2015:30100 lon/lat) from longitude `west`:
    relief that repeats round the body, a dome on the grid's seam and caps at the poles."""
    import numpy as np
    from osgeo import gdal, osr

    gdal.UseExceptions()
    lat = 89.5 - np.arange(180.0)[:, None]
    lon = west + 0.5 + np.arange(360.0)[None, :]
    rad = np.radians
    z = 800 * np.sin(3 * rad(lon)) * np.cos(2 * rad(lat)) + 300 * np.sin(rad(lat)) ** 2
    # A dome centred on the seam (longitude `west`) at 20 N.
    d = np.degrees(np.arccos(np.clip(
        np.sin(rad(lat)) * np.sin(rad(20)) +
        np.cos(rad(lat)) * np.cos(rad(20)) * np.cos(rad(lon - west)), -1, 1)))
    z = z + 2000 * np.exp(-(d / 12) ** 2)
    srs = osr.SpatialReference()
    srs.SetFromUserInput("IAU_2015:30100")
    ds = gdal.GetDriverByName("GTiff").Create(str(path), 360, 180, 1, gdal.GDT_Float32)
    ds.SetGeoTransform((west, 1.0, 0.0, 90.0, 0.0, -1.0))
    ds.SetProjection(srs.ExportToWkt())
    ds.GetRasterBand(1).WriteArray(z.astype("float32"))
    ds = None
    return path


def pixel_areas(labels):
    """Area on the Moon's sphere of each label's pixels (1-degree rows from pole to pole)."""
    import numpy as np

    rows, cols = labels.shape
    north = np.radians(90 - np.arange(rows) * 180 / rows)
    south = np.radians(90 - (np.arange(rows) + 1) * 180 / rows)
    band = MOON_RADIUS ** 2 * math.radians(360 / cols) * (np.sin(north) - np.sin(south))
    weights = np.repeat(band[:, None], cols, axis=1)
    return np.bincount(labels.ravel(), weights=weights.ravel())


@pytest.fixture(scope="module", params=[0.0, -180.0], ids=["0..360", "-180..180"])
def global_out(request, cli, tmp_path_factory):
    west = request.param
    base = tmp_path_factory.mktemp("global")
    dem = global_moon_dem(base / "global.tif", west)
    out = base / "out"
    done = cli("segment", dem, "-o", out, "-q")
    assert done.returncode == 0, done.stderr
    return west, out


def test_global_polygons_split_at_the_seam_valid_and_within_range(global_out):
    import geopandas as gpd
    import rasterio
    from osgeo import ogr
    from shapely.geometry import shape

    west, out = global_out
    labels = rasterio.open(out / "labels.tif").read(1)
    # The relief makes what the test is about: a region on both sides of the seam and
    # regions on the pole rows.
    assert set(labels[:, 0]) & set(labels[:, -1])
    assert labels[0].min() > 0 and labels[-1].min() > 0

    gdf = gpd.read_file(out / "regions.geojson")
    assert gdf.crs.is_geographic
    assert gdf.crs.ellipsoid.semi_major_metre == pytest.approx(MOON_RADIUS)
    assert gdf.geometry.is_valid.all()
    ds = ogr.Open(str(out / "regions.geojson"))
    assert all(f.GetGeometryRef().IsValid() for f in ds.GetLayer(0))
    minx, miny, maxx, maxy = gdf.total_bounds
    assert west <= minx and maxx <= west + 360 and -90 <= miny and maxy <= 90
    assert (minx, maxx) == (west, west + 360)  # pieces on both sides of the seam
    # No piece wider than 180 degrees unless it is a pole cap.
    features = json.loads((out / "regions.geojson").read_text())["features"]
    for f in features:
        g = shape(f["geometry"])
        for part in getattr(g, "geoms", [g]):
            x0, y0, x1, y1 = part.bounds
            assert x1 - x0 <= 180 or y1 == 90 or y0 == -90, (f["id"], part.bounds)
    # A region that crosses the seam has a piece at each end of the longitude range.
    across = set(labels[:, 0]) & set(labels[:, -1])
    for f in features:
        if f["id"] in across:
            x0, _, x1, _ = shape(f["geometry"]).bounds
            assert (x0, x1) == (west, west + 360)


def test_global_polygon_areas_on_the_body(global_out):
    import numpy as np
    import rasterio
    from pyproj import Geod
    from shapely.geometry import shape

    west, out = global_out
    labels = rasterio.open(out / "labels.tif").read(1)
    expected = pixel_areas(labels)
    geod = Geod(a=MOON_RADIUS, b=MOON_RADIUS)
    body = 4 * math.pi * MOON_RADIUS ** 2
    total = 0.0
    for f in json.loads((out / "regions.geojson").read_text())["features"]:
        area = geod.geometry_area_perimeter(shape(f["geometry"]))[0]
        # Geodesic areas are known modulo the body's: a region round both poles reads as
        # minus what it leaves out.
        want = expected[f["id"]]
        area += body * round((want - area) / body)
        assert area == pytest.approx(want, rel=1e-3), f["id"]
        total += area
    assert total == pytest.approx(body, rel=5e-3)
    assert np.isclose(expected.sum(), body, rtol=1e-9)


def test_global_polygons_rasterise_back_to_their_pixels(global_out):
    import numpy as np
    import rasterio
    from rasterio.features import rasterize
    from rasterio.transform import from_origin
    from shapely.geometry import shape

    west, out = global_out
    with rasterio.open(out / "labels.tif") as src:
        labels = src.read(1)
        assert src.transform == from_origin(west, 90, 1, 1)
    features = json.loads((out / "regions.geojson").read_text())["features"]
    burnt = rasterize(((shape(f["geometry"]), f["id"]) for f in features),
                      out_shape=labels.shape, transform=from_origin(west, 90, 1, 1),
                      fill=0, dtype="uint32")
    counts = np.bincount(labels.ravel(), minlength=len(features) + 1)
    assert np.array_equal(np.bincount(burnt.ravel(), minlength=counts.size), counts)
    assert np.array_equal(burnt, labels)


@pytest.fixture(scope="module")
def ldem4_out(cli, tmp_path_factory):
    """LOLA's LDEM_4 (0..360, an equirectangular grid centred on 180 E whose rounded map
    scale spans 360.00006 x 180.00003 degrees), segmented."""
    from conftest import SOURCE_DIR

    ldem = SOURCE_DIR / "tests" / "data" / "moon_lola_ldem4" / "LDEM_4.LBL"
    assert ldem.exists(), "tests/data holds LDEM_4 (tests/data/README.md)"
    out = tmp_path_factory.mktemp("ldem4") / "out"
    done = cli("segment", ldem, "-o", out, "-q")
    assert done.returncode == 0, done.stderr
    return out


def test_ldem4_polygons_valid_within_range_and_give_their_pixels_back(ldem4_out):
    import geopandas as gpd
    import numpy as np
    import rasterio
    from pyproj import Geod
    from rasterio.features import rasterize
    from rasterio.transform import from_origin
    from shapely.geometry import shape

    gdf = gpd.read_file(ldem4_out / "regions.geojson")
    assert gdf.geometry.is_valid.all()
    minx, miny, maxx, maxy = gdf.total_bounds
    assert (minx, miny, maxx, maxy) == (0, -90, 360, 90)
    labels = rasterio.open(ldem4_out / "labels.tif").read(1)
    features = json.loads((ldem4_out / "regions.geojson").read_text())["features"]
    for f in features:
        g = shape(f["geometry"])
        for part in getattr(g, "geoms", [g]):
            x0, y0, x1, y1 = part.bounds
            assert x1 - x0 <= 180 or y1 == 90 or y0 == -90, (f["id"], part.bounds)
    # On the 0.25-degree lon/lat grid of its pixels, each region burns its own pixels.
    burnt = rasterize(((shape(f["geometry"]), f["id"]) for f in features),
                      out_shape=labels.shape, transform=from_origin(0, 90, 0.25, 0.25),
                      fill=0, dtype="uint32")
    assert np.array_equal(burnt, labels)
    # Areas on the Moon's sphere: each region's that of its pixels, together the Moon's.
    expected = pixel_areas(labels)
    geod = Geod(a=MOON_RADIUS, b=MOON_RADIUS)
    body = 4 * math.pi * MOON_RADIUS ** 2
    total = 0.0
    for f in features:
        area = geod.geometry_area_perimeter(shape(f["geometry"]))[0]
        want = expected[f["id"]]
        area += body * round((want - area) / body)
        assert area == pytest.approx(want, rel=1e-3), f["id"]
        total += area
    assert total == pytest.approx(body, rel=5e-3)


def test_ldem4_gpkg_to_lonlat_as_documented(cli, ldem4_out, monkeypatch):
    """regions.gpkg stays in LDEM_4's CRS; docs/outputs.md's to_crs with +lon_wrap takes it
    to 0..360 lon/lat whole: valid, and rasterised it gives labels.tif back."""
    import re

    import numpy as np
    import rasterio
    from rasterio.features import rasterize
    from rasterio.transform import from_origin

    from conftest import SOURCE_DIR

    work = ldem4_out.parent / "gpkg"
    work.mkdir()
    ldem = SOURCE_DIR / "tests" / "data" / "moon_lola_ldem4" / "LDEM_4.LBL"
    done = cli("segment", ldem, "-o", work / "out", "-q", "--format", "GPKG")
    assert done.returncode == 0, done.stderr
    text = (SOURCE_DIR / "docs" / "outputs.md").read_text()
    blocks = [b for b in re.findall(r"```python\n(.*?)```", text, re.S) if "lon_wrap" in b]
    assert len(blocks) == 1
    lines = blocks[0].splitlines()
    indent = min(len(l) - len(l.lstrip()) for l in lines if l.strip())
    monkeypatch.chdir(work)
    scope = {}
    exec("\n".join(l[indent:] for l in lines), scope)
    lonlat = scope["lonlat"]
    assert lonlat.geometry.is_valid.all()
    minx, miny, maxx, maxy = lonlat.total_bounds
    assert 0 <= minx < 1e-6 and 360 - 1e-6 < maxx <= 360 and (miny, maxy) == (-90, 90)
    labels = rasterio.open(work / "out" / "labels.tif").read(1)
    burnt = rasterize(zip(lonlat.geometry, lonlat["id"]), out_shape=labels.shape,
                      transform=from_origin(0, 90, 0.25, 0.25), fill=0, dtype="uint32")
    assert np.array_equal(burnt, labels)
