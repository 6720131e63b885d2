"""terrain.segment: the same labels as the command line, arrays in, errors, progress."""

import threading
import time

import numpy as np
import pytest
from osgeo import gdal, osr

import terrain
from conftest import SAMPLE_FILES

gdal.UseExceptions()


def read_labels(path):
    return gdal.Open(str(path)).ReadAsArray()


@pytest.mark.parametrize("name", sorted(SAMPLE_FILES))
def test_labels_identical_to_the_cli(name, cli, tmp_path):
    sample = SAMPLE_FILES[name]
    out = tmp_path / "seg"
    done = cli("segment", sample, "-o", out, "-q")
    assert done.returncode == 0, done.stderr
    result = terrain.segment(sample)
    expected = read_labels(out / "labels.tif")
    assert result.labels.shape == expected.shape
    assert np.array_equal(result.labels, expected)
    assert result.region_count == len(result.regions["id"]) == int(expected.max())
    assert str(result.region_count) + " regions" in done.stdout


def test_options_reach_the_library(cli, moon, tmp_path):
    out = tmp_path / "seg"
    args = ["--persistence", "5", "--area-ratio", "1", "--cost", "standard", "--rings", "3"]
    assert cli("segment", moon, "-o", out, "-q", *args).returncode == 0
    result = terrain.segment(moon, persistence=5, area_ratio=1, cost="standard", rings=3)
    assert np.array_equal(result.labels, read_labels(out / "labels.tif"))
    default = terrain.segment(moon)
    assert not np.array_equal(result.labels, default.labels)


def test_read_options_reach_a_path(cli, tmp_path):
    # Values that are radii from Vesta's centre read as heights: another mesh, other regions.
    vesta = str(SAMPLE_FILES["vesta"])
    out = tmp_path / "seg"
    assert cli("segment", vesta, "-o", out, "-q", "--elevation", "height").returncode == 0
    result = terrain.segment(vesta, elevation="height")
    assert np.array_equal(result.labels, read_labels(out / "labels.tif"))
    assert not np.array_equal(result.labels, terrain.segment(vesta).labels)


def test_array_and_geotransform_equal_the_file(moon):
    from_file = terrain.segment(moon)
    ds = gdal.Open(moon)
    band = ds.GetRasterBand(1)
    values = band.ReadAsArray().astype(np.float64)
    values[values == band.GetNoDataValue()] = np.nan
    values = values * (band.GetScale() or 1) + (band.GetOffset() or 0)
    from_array = terrain.segment(values, ds.GetGeoTransform(), ds.GetProjection())
    assert np.array_equal(from_array.labels, from_file.labels)
    # terrain.read_dem's Dem, and its arrays handed back.
    dem = terrain.read_dem(moon)
    assert dem.values.shape == from_file.labels.shape
    assert np.array_equal(terrain.segment(dem).labels, from_file.labels)
    again = terrain.segment(dem.values, dem.geotransform, dem.crs)
    assert np.array_equal(again.labels, from_file.labels)
    for key in ("area_m2", "field_mean", "point_x"):
        assert np.array_equal(again.regions[key], from_file.regions[key])


def test_rasterio_arrays(moon):
    import rasterio  # installed by the set-up: a missing client fails
    with rasterio.open(moon) as src:
        values = src.read(1, masked=True).astype(np.float64) * src.scales[0] + src.offsets[0]
        result = terrain.segment(values, src.transform, src.crs)
    assert np.array_equal(result.labels, terrain.segment(moon).labels)


def synthetic_dem(n=64):
    y, x = np.mgrid[0:n, 0:n] / n
    z = 200 * np.sin(6 * x) * np.cos(5 * y) + 50 * np.sin(17 * x * y)
    z[:3, :3] = np.nan  # NoData
    return z


def test_authority_string_equals_wkt_and_file(tmp_path):
    z = synthetic_dem()
    gt = (380000.0, 30.0, 0.0, 3800000.0, 0.0, -30.0)
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32611)
    by_code = terrain.segment(z, gt, "EPSG:32611")
    by_wkt = terrain.segment(z, gt, srs.ExportToWkt())
    assert by_code.dem.body == "Earth"
    assert np.array_equal(by_code.labels, by_wkt.labels)
    path = tmp_path / "z.tif"
    ds = gdal.GetDriverByName("GTiff").Create(str(path), z.shape[1], z.shape[0], 1,
                                              gdal.GDT_Float64)
    ds.SetGeoTransform(gt)
    ds.SetProjection(srs.ExportToWkt())
    ds.GetRasterBand(1).SetNoDataValue(-9999)
    ds.GetRasterBand(1).WriteArray(np.where(np.isnan(z), -9999, z))
    ds = None
    from_file = terrain.segment(path)
    assert np.array_equal(from_file.labels, by_code.labels)
    assert np.all(by_code.labels[:3, :3] == 0)  # NoData pixels carry no region
    assert (by_code.labels[np.isfinite(z)] > 0).mean() > 0.99


def test_errors_raise_terrain_error(moon):
    with pytest.raises(terrain.Error, match=r"^read: '/no/such\.tif' does not exist"):
        terrain.segment("/no/such.tif")
    with pytest.raises(terrain.Error, match=r"^segment: --persistence must be a number >= 0$"):
        terrain.segment(moon, persistence=-1)
    with pytest.raises(terrain.Error, match=r"^field: unknown field 'slope'"):
        terrain.segment(moon, field="slope")
    with pytest.raises(terrain.Error, match="2-D"):
        terrain.segment(np.zeros(10))
    with pytest.raises(terrain.Error, match="not a CRS"):
        terrain.segment(synthetic_dem(), (0, 1, 0, 0, 0, -1), "EPSG:nonsense")
    with pytest.raises(terrain.Error, match="rings or radius"):
        terrain.segment(moon, rings=3, radius=100)
    with pytest.raises(TypeError, match="unknown option 'persistance'"):
        terrain.segment(moon, persistance=3)
    assert issubclass(terrain.Error, RuntimeError)


def test_progress_and_cancel(moon):
    seen = []
    terrain.segment(moon, progress=lambda f, msg: seen.append(f))
    assert seen and seen[-1] == pytest.approx(1.0)
    assert all(b >= a - 1e-12 for a, b in zip(seen, seen[1:]))
    with pytest.raises(terrain.Error, match="cancelled"):
        terrain.segment(moon, progress=lambda f, msg: f < 0.5)

    class Stop(Exception):
        pass

    def fail(f, msg):
        if f > 0.3:
            raise Stop("from the callback")

    with pytest.raises(Stop, match="from the callback"):
        terrain.segment(moon, progress=fail)


def test_the_gil_is_released_during_the_work():
    vesta = str(SAMPLE_FILES["vesta"])
    dem = terrain.read_dem(vesta)
    done = threading.Event()
    out = {}

    def work():
        out["result"] = terrain.segment(dem)
        done.set()

    thread = threading.Thread(target=work)
    ticks = 0
    thread.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    thread.join()
    assert out["result"].region_count > 1
    # Holding the GIL for the whole segmentation (~1 s) would leave this thread a few ticks.
    assert ticks > 50


def test_write_gives_the_cli_directory(cli, moon, tmp_path):
    result = terrain.segment(moon)
    files = result.write(tmp_path / "py")
    assert files[0] == "labels.tif" and files[-1] == "run.json"
    assert cli("segment", moon, "-o", tmp_path / "cli", "-q").returncode == 0
    for name in ("labels.tif", "regions.geojson", "adjacency.json", "adjacency.graphml"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    with pytest.raises(terrain.Error, match="already exists"):
        result.write(tmp_path / "py")


def test_mesh_files(cli, moon, tmp_path):
    mesh = tmp_path / "moon.ply"
    assert cli("mesh", moon, "-o", mesh, "-q").returncode == 0
    result = terrain.segment(mesh)
    assert result.labels is None
    assert len(result.vertex_labels) == result.regions["vertex_count"].sum()
    assert set(np.unique(result.vertex_labels)) == set(result.regions["id"])


def test_help_shows_the_options():
    assert "persistence" in terrain.segment.__doc__
    assert "geotransform" in terrain.segment.__doc__
    assert "area_ratios" in terrain.sweep.__doc__ or "area ratio" in terrain.sweep.__doc__


def test_min_area_is_the_cli_and_an_area_ratio(cli, moon, tmp_path):
    out = tmp_path / "seg"
    assert cli("segment", moon, "-o", out, "-q", "--min-area", "150km2").returncode == 0
    by_text = terrain.segment(moon, min_area="150km2")
    by_number = terrain.segment(moon, min_area=1.5e8)
    assert np.array_equal(by_text.labels, read_labels(out / "labels.tif"))
    assert np.array_equal(by_number.labels, by_text.labels)
    import json
    ratio = json.loads((out / "run.json").read_text())["parameters"]["area_ratio_percent"]
    by_ratio = terrain.segment(moon, area_ratio=ratio)
    assert np.array_equal(by_ratio.labels, by_text.labels)
    with pytest.raises(terrain.Error, match="not both"):
        terrain.segment(moon, min_area="150km2", area_ratio=0.5)
    with pytest.raises(terrain.Error, match="min-area"):
        terrain.segment(moon, min_area="150 acres")
    sweep = terrain.sweep(moon, min_areas=["150km2", "50km2"])
    assert [s.min_area for s in sweep.scales] == [5e7, 1.5e8]
    # The finest scale is a plain segment at its area (the coarser one continues from it).
    assert np.array_equal(sweep.scales[0].labels, terrain.segment(moon, min_area="50km2").labels)
    graph = terrain.reeb_graph(moon, min_area="150km2")
    assert graph.critical_before > len(graph.nodes["node"])


def test_options_given_by_name_read_back_and_refuse_other_names(moon):
    # The library holds values; the module reads the command line's names and gives them back.
    options = terrain._terrain.SegmentOptions()
    assert (options.field, options.cost, options.absorbed, options.min_area, options.window) == (
        "shape-index", "auto", "auto", "", "disk")
    for attribute, names in (("field", ("sdf", "height", "shape-index")),
                             ("cost", ("graph", "standard", "auto")),
                             ("absorbed", ("divide", "whole", "auto")),
                             ("window", ("ball", "disk")),
                             ("min_area", ("5km2", "20000ha", "auto", "1e6"))):
        for name in names:
            setattr(options, attribute, name)
            assert getattr(options, attribute) == name
    options.min_area = 1.5e8  # a number of m^2, kept as Python writes it (run.json records it)
    assert options.min_area == "150000000.0"
    options.min_area = None
    assert options.min_area == ""
    for given, line in (
            ({"cost": "cheap"}, "segment: unknown cost 'cheap'; use graph or standard"),
            ({"absorbed": "bad"}, "segment: --absorbed is divide, whole or auto; 'bad' is none "
                                  "of them"),
            ({"field": "Height"}, "field: unknown field 'Height'; use shape-index, sdf or height"),
            ({"min_area": "AUTO"}, "segment: --min-area takes an area above 0 in m^2 or with a "
                                   "unit (5km2, 2000m2, 3ha); 'AUTO' is not one"),
            ({"min_area": -5}, "segment: --min-area takes an area above 0 in m^2 or with a unit "
                               "(5km2, 2000m2, 3ha); '-5.0' is not one"),
            ({"frame": "sideways"}, "mesh: the frame must be body, map or auto, not 'sideways'"),
            ({"window": "cube", "radius": 30000}, "options: window must be disk or ball, not "
                                                  "'cube'")):
        with pytest.raises(terrain.Error) as error:
            terrain.segment(moon, **given)
        assert str(error.value) == line


def test_window_is_the_cli_and_disk_by_default(cli, moon, tmp_path):
    # --radius of about 4 pixels of the 7.6 km crop.
    disk = terrain.shape_index(moon, radius=30000)
    assert np.array_equal(disk, terrain.shape_index(moon, radius=30000, window="disk"))
    ball = terrain.shape_index(moon, radius=30000, window="ball")
    assert not np.array_equal(disk, ball)
    out = tmp_path / "ball.tif"
    assert cli("field", moon, "--radius", "30000", "--window", "ball", "-o", out,
               "-q").returncode == 0
    ds = gdal.Open(str(out))
    assert np.array_equal(ball, ds.ReadAsArray(), equal_nan=True)
    with pytest.raises(terrain.Error, match="window must be disk or ball"):
        terrain.shape_index(moon, radius=30000, window="cube")


def test_the_default_regions_carry_their_field_scale(moon, cli, tmp_path):
    # With no scale option each region records the radius most of its pixels took, as the
    # command line's regions.geojson does; a single scale has no such column.
    import json
    result = terrain.segment(moon)
    scale = result.regions["field_scale_m"]
    assert len(scale) == result.region_count
    out = tmp_path / "seg"
    assert cli("segment", moon, "-o", out, "-q").returncode == 0
    features = json.loads((out / "regions.geojson").read_text())["features"]
    by_id = {f["properties"]["id"]: f["properties"]["field_scale_m"] for f in features}
    assert [by_id[int(i)] for i in result.regions["id"]] == list(scale)
    radii = json.loads((out / "run.json").read_text())["parameters"]["radii_m"]
    assert set(scale[result.regions["vertex_count"] > 0]) <= set(radii)
    assert len(set(scale)) >= 2
    assert "field_scale_m" not in terrain.segment(moon, area_ratio=0.5).regions


def test_the_default_regions_carry_their_range_of_area_thresholds(moon, cli, tmp_path):
    # With --min-area auto each region records the area thresholds it lives over: from the
    # map's own to the first doubling at which its seed is cancelled or has taken in its
    # neighbours. The table, labels.tif's attribute table, regions.geojson and run.json say
    # the same; a single scale has no such columns.
    import json
    result = terrain.segment(moon)
    lo, hi = result.regions["min_area_from_m2"], result.regions["min_area_to_m2"]
    seeded = result.regions["vertex_count"] > 0
    out = tmp_path / "seg"
    assert cli("segment", moon, "-o", out, "-q").returncode == 0
    run = json.loads((out / "run.json").read_text())["parameters"]
    floor = run["min_area_m2"]
    assert np.all(lo[seeded] == floor) and np.all(hi[seeded] >= 2 * floor)
    levels = np.log2(hi[seeded] / floor)
    whole = hi[seeded] == hi.max()
    assert np.allclose(levels[~whole], np.round(levels[~whole]))
    assert whole.sum() >= 1 and (~whole).sum() > seeded.sum() // 2
    features = json.loads((out / "regions.geojson").read_text())["features"]
    by_id = {f["properties"]["id"]: f["properties"]["min_area_to_m2"] for f in features}
    assert [by_id[int(i)] for i in result.regions["id"]] == list(hi)
    labels = gdal.Open(str(out / "labels.tif"))
    rat = labels.GetRasterBand(1).GetDefaultRAT()
    names = [rat.GetNameOfCol(c) for c in range(rat.GetColumnCount())]
    column = names.index("min_area_to_m2")
    assert [rat.GetValueAsDouble(r, column) for r in range(rat.GetRowCount())] == \
        pytest.approx(list(hi))
    ladder = run["area_range"]
    assert ladder["step"] == 2
    assert ladder["thresholds_m2"][0] == floor
    for t, n in zip(ladder["thresholds_m2"], ladder["regions"]):
        assert n == int((hi > t).sum())
    # A nested sweep from the map's threshold up: a region whose range passes a level has a
    # seed there, so the sweep's regions at that level are at least as many.
    areas = [floor * 2 ** k for k in range(0, 5)]
    sweep = terrain.sweep(moon, min_areas=areas, radius="auto")
    assert sweep.scales[0].region_count == result.region_count
    for area, scale in zip(areas[1:], sweep.scales[1:]):
        found = int((scale.regions["vertex_count"] > 0).sum())
        assert int((hi > area).sum()) <= found < seeded.sum()
    single = terrain.segment(moon, area_ratio=0.5).regions
    assert "min_area_from_m2" not in single and "min_area_to_m2" not in single


def test_the_crater_table_in_python_and_files(moon, cli, tmp_path):
    # The craters read from the regions: a GeoDataFrame of points at their centres in the
    # body's lon/lat, the same rows as craters.csv; craters.scc holds them for craterstats
    # with the DEM's valid area; craters=False / --craters off make none.
    import csv
    result = terrain.segment(moon)
    craters = result.craters
    assert craters is not None and len(craters) > 0
    assert craters.crs is not None and craters.crs.is_geographic
    assert np.allclose(craters.geometry.x, craters["lon"]) and np.allclose(craters.geometry.y,
                                                                          craters["lat"])
    assert (craters["diameter_m"] > 0).all() and (craters["depth_m"] > 0).all()
    assert craters["confidence"].between(0.2, 1).all()  # docs/craters.md: kept at 0.2 or more
    ids = set(result.regions["id"])
    for floor, rims in zip(craters["floor_region"], craters["rim_regions"]):
        assert floor in ids and rims and set(rims) <= ids
    mean = dict(zip(result.regions["id"], result.regions["field_mean"]))
    assert all(mean[f] < 50 for f in craters["floor_region"])
    out = tmp_path / "seg"
    assert cli("segment", moon, "-o", out, "-q").returncode == 0
    with open(out / "craters.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(craters)
    assert [float(r["diameter_m"]) for r in rows] == pytest.approx(list(craters["diameter_m"]))
    assert [float(r["lon"]) for r in rows] == pytest.approx(list(craters["lon"]))
    scc = (out / "craters.scc").read_text().splitlines()
    area = [line for line in scc if line.startswith("Total_area")][0]
    assert float(area.split("=")[1].split("<")[0]) == pytest.approx(
        result.regions["area_m2"].sum() / 1e6, rel=1e-9)
    start = scc.index("crater = {diam,lon,lat")
    table = [line.split("\t") for line in scc[start + 1:scc.index("}", start)]]
    assert [float(t[0]) for t in table] == pytest.approx(list(craters["diameter_m"] / 1000))
    assert [float(t[1]) for t in table] == pytest.approx(list(craters["lon"]))
    # craters.png: the two panels, with the craters' dots drawn in blue.
    png = gdal.Open(str(out / "craters.png"))
    assert (png.RasterXSize, png.RasterYSize, png.RasterCount) == (1000, 500, 3)
    r, g, b = (png.GetRasterBand(i).ReadAsArray().astype(int) for i in (1, 2, 3))
    assert ((b > 150) & (r < 100)).sum() > 10 * len(craters)
    # craters.geojson: a centre and a rim ring per crater, the ring on the body's sphere at
    # the crater's radius from the centre, in the Moon's geographic CRS.
    import geopandas
    layer = geopandas.read_file(out / "craters.geojson")
    assert layer.crs is not None and "Moon" in layer.crs.name
    centres, rims = layer[layer["kind"] == "centre"], layer[layer["kind"] == "rim"]
    assert len(centres) == len(rims) == len(craters)
    assert np.allclose(centres.geometry.x, craters["lon"])
    radius = 1737400.0
    for (_, c), (_, r) in zip(centres.iterrows(), rims.iterrows()):
        lon, lat = np.radians(np.array(r.geometry.exterior.coords)).T
        lon0, lat0 = np.radians(c.geometry.x), np.radians(c.geometry.y)
        cos = (np.sin(lat) * np.sin(lat0) + np.cos(lat) * np.cos(lat0) * np.cos(lon - lon0))
        distance = radius * np.arccos(np.clip(cos, -1, 1))
        assert np.allclose(distance, c["diameter_m"] / 2, rtol=0.03)
    assert terrain.segment(moon, craters=False).craters is None
    with pytest.raises(TypeError, match="unknown option 'craters'"):
        terrain.sweep(moon, area_ratios=[1], craters=False)
    off = tmp_path / "off"
    assert cli("segment", moon, "-o", off, "-q", "--craters", "off").returncode == 0
    assert not any((off / name).exists()
                   for name in ("craters.csv", "craters.scc", "craters.geojson", "craters.png"))


def test_a_geopackage_holds_the_craters_beside_the_regions(moon, cli, tmp_path):
    # With --format GPKG, regions.gpkg also holds the layers "craters" (points) and
    # "crater_rims" (polygons) in the Moon's geographic CRS, the rows of craters.csv, and the
    # file's bytes repeat run to run.
    import csv
    import geopandas
    out, again = tmp_path / "seg", tmp_path / "again"
    for d in (out, again):
        assert cli("segment", moon, "-o", d, "-q", "--format", "GPKG").returncode == 0
    assert (out / "regions.gpkg").read_bytes() == (again / "regions.gpkg").read_bytes()
    with open(out / "craters.csv") as f:
        rows = list(csv.DictReader(f))
    centres = geopandas.read_file(out / "regions.gpkg", layer="craters")
    rims = geopandas.read_file(out / "regions.gpkg", layer="crater_rims")
    assert len(rows) > 0 and len(centres) == len(rims) == len(rows)
    assert centres.crs.is_geographic and "Moon" in centres.crs.name
    assert rims.crs == centres.crs
    assert list(centres["id"]) == [int(r["id"]) for r in rows]
    assert list(centres.geometry.x) == pytest.approx([float(r["lon"]) for r in rows])
    assert (rims.geometry.geom_type == "Polygon").all()
    assert all(r.contains(c) for r, c in zip(rims.geometry, centres.geometry))
    regions = geopandas.read_file(out / "regions.gpkg", layer="regions")
    assert len(regions) > 0
