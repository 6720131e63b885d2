"""The outputs read back through the GIS clients Debian ships (networkx, GDAL, geopandas,
rasterio), exactly as docs/outputs.md tells a user to."""

import json
import re

import pytest

from conftest import SOURCE_DIR

OUTPUTS_MD = SOURCE_DIR / "docs" / "outputs.md"


def doc_snippet(marker):
    """The ```python block of docs/outputs.md that contains `marker`."""
    blocks = re.findall(r"```python\n(.*?)```", OUTPUTS_MD.read_text(), re.S)
    found = [b for b in blocks if marker in b]
    assert len(found) == 1, f"docs/outputs.md has no single python block with {marker!r}"
    # The blocks are indented inside list items.
    lines = found[0].splitlines()
    indent = min(len(l) - len(l.lstrip()) for l in lines if l.strip())
    return "\n".join(l[indent:] for l in lines)


@pytest.fixture(scope="module")
def moon_out(cli, moon, tmp_path_factory):
    out = tmp_path_factory.mktemp("gis") / "out"
    done = cli("segment", moon, "-o", out, "-q")
    assert done.returncode == 0, done.stderr
    return out


def test_networkx_loads_adjacency_json_as_documented(moon_out, monkeypatch):
    import networkx as nx  # installed by the set-up: a missing client fails
    code = doc_snippet("adjacency.json")
    monkeypatch.chdir(moon_out.parent)
    scope = {}
    exec(compile(code, str(OUTPUTS_MD), "exec"), scope)
    graph = scope["graph"]
    assert isinstance(graph, nx.Graph) and not graph.is_directed()
    data = json.loads((moon_out / "adjacency.json").read_text())
    assert graph.number_of_nodes() == len(data["nodes"]) > 1
    assert graph.number_of_edges() == len(data["edges"]) > 0
    edge = data["edges"][0]
    assert graph.has_edge(edge["source"], edge["target"])
    assert graph.nodes[1]["landform"] == data["nodes"][0]["landform"]


def hills(size=96):
    """A smooth synthetic relief: a few Gaussian hills and pits, metres."""
    import numpy as np  # installed by the set-up: a missing client fails
    y, x = np.mgrid[0:size, 0:size].astype(float)
    z = np.zeros_like(x)
    for cx, cy, h, s in ((25, 30, 40, 9), (70, 25, -30, 11), (50, 70, 35, 13), (15, 80, -20, 8)):
        z += h * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * s * s))
    return z + 100


def write_raster(path, values, driver, geotransform=None, crs=None):
    from osgeo import gdal, osr

    gdal.UseExceptions()
    mem = gdal.GetDriverByName("MEM").Create("", values.shape[1], values.shape[0], 1,
                                             gdal.GDT_UInt16 if driver == "PNG" else gdal.GDT_Float32)
    if geotransform:
        mem.SetGeoTransform(geotransform)
    if crs:
        srs = osr.SpatialReference()
        srs.SetFromUserInput(crs)
        mem.SetProjection(srs.ExportToWkt(["FORMAT=WKT2_2019"]))
    mem.GetRasterBand(1).WriteArray(values)
    gdal.GetDriverByName(driver).CreateCopy(str(path), mem)
    return path


def test_segment_help_names_format(cli):
    done = cli("segment", "--help")
    assert done.returncode == 0
    usage = next(l for l in done.stdout.splitlines() if l.startswith("Usage:"))
    assert "--format" in usage


def test_an_image_without_geotransform_warns_once(cli, tmp_path):
    png = write_raster(tmp_path / "dem.png", hills().round(), "PNG")
    done = cli("segment", png, "-o", tmp_path / "out", "-q")
    assert done.returncode == 0, done.stderr
    warnings = [l for l in done.stderr.splitlines() if "warning" in l]
    assert len(warnings) == 1, done.stderr
    assert "no geotransform" in warnings[0] and "--pixel-size" in warnings[0]
    # With the pixel size given, still one warning (no CRS), naming the size as given.
    done = cli("segment", png, "-o", tmp_path / "out2", "-q", "--pixel-size", "10")
    warnings = [l for l in done.stderr.splitlines() if "warning" in l]
    assert done.returncode == 0 and len(warnings) == 1, done.stderr
    assert "given --pixel-size" in warnings[0]


def test_georeferenced_dem_gives_no_warning(cli, moon, tmp_path):
    done = cli("segment", moon, "-o", tmp_path / "out", "-q")
    assert done.returncode == 0 and "warning" not in done.stderr, done.stderr


def test_labels_tif_is_a_cloud_optimized_geotiff(cli, tmp_path):
    from osgeo_utils.samples import validate_cloud_optimized_geotiff as cog

    from conftest import SAMPLE_FILES

    for name in ("vesta", "moon4c", "moon1g"):
        out = tmp_path / name
        assert cli("segment", SAMPLE_FILES[name], "-o", out, "-q").returncode == 0
        warnings, errors, details = cog.validate(str(out / "labels.tif"), full_check=True)
        assert not errors, (name, errors)
    # The sweep's labels.tif, one band per scale, likewise.
    out = tmp_path / "sweep"
    assert cli("sweep", SAMPLE_FILES["vesta"], "-o", out, "-q").returncode == 0
    warnings, errors, details = cog.validate(str(out / "labels.tif"), full_check=True)
    assert not errors, errors


def test_labels_tif_has_internal_overviews(cli, tmp_path):
    from osgeo import gdal

    from conftest import SAMPLE_FILES

    out = tmp_path / "vesta"
    assert cli("segment", SAMPLE_FILES["vesta"], "-o", out, "-q").returncode == 0
    ds = gdal.Open(str(out / "labels.tif"))
    band = ds.GetRasterBand(1)
    assert band.GetOverviewCount() == 3  # 512 px: 256, 128, 64
    assert not (out / "labels.tif.ovr").exists()  # internal
    full = set(band.ReadAsArray().ravel().tolist())
    overview = band.GetOverview(0)
    assert (overview.XSize, overview.YSize) == (256, 256)
    # Nearest: every overview pixel is a region id of the full grid.
    assert set(overview.ReadAsArray().ravel().tolist()) <= full
    # The colour table (65 536 entries, 384 KB in a UInt16 TIFF) is in the full grid's
    # directory only: the overviews are plain grey ids, the file a quarter of what four
    # copies made it.
    assert band.GetColorTable() is not None and band.GetColorTable().GetCount() == 65536
    for k in range(band.GetOverviewCount()):
        assert band.GetOverview(k).GetColorTable() is None
    assert (out / "labels.tif").stat().st_size < 600_000


@pytest.fixture(scope="module")
def local_dem(tmp_path_factory):
    path = tmp_path_factory.mktemp("local") / "local.tif"
    return write_raster(path, hills(), "GTiff", (500000.0, 10.0, 0.0, 4000000.0, 0.0, -10.0))


@pytest.mark.parametrize("fmt,name", [("GeoJSON", "regions.geojson"), ("GPKG", "regions.gpkg")])
def test_dem_without_crs_makes_no_lonlat_claim(cli, local_dem, tmp_path, fmt, name):
    import geopandas as gpd  # installed by the set-up: a missing client fails
    from osgeo import ogr

    out = tmp_path / "out"
    done = cli("segment", local_dem, "-o", out, "-q", "--format", fmt)
    assert done.returncode == 0, done.stderr
    warnings = [l for l in done.stderr.splitlines() if "warning" in l]
    assert len(warnings) == 1 and "no CRS" in warnings[0], done.stderr
    files = [name] + (["adjacency.geojson"] if fmt == "GeoJSON" else [])
    for file in files:
        gdf = gpd.read_file(out / file)
        assert gdf.crs is not None, file  # not left to default to WGS 84
        assert not gdf.crs.is_geographic and gdf.crs.to_epsg() is None, file
        assert gdf.crs.to_epsg() != 4326
        ds = ogr.Open(str(out / file))  # kept: the layer lives in it
        srs = ds.GetLayer(0).GetSpatialRef()
        assert srs is not None and srs.IsLocal() and not srs.IsGeographic(), file
        # The coordinates are the DEM's metres, inside its footprint.
        xmin, ymin, xmax, ymax = gdf.total_bounds
        assert 500000 <= xmin < xmax <= 500960 and 3999040 <= ymin < ymax <= 4000000, file


@pytest.mark.parametrize("fmt", ["KML", "LIBKML"])
def test_kml_refused_for_planetary_and_local_dems(cli, local_dem, tmp_path, fmt):
    from conftest import SAMPLE_FILES

    for dem in (SAMPLE_FILES["vesta"], SAMPLE_FILES["moon4c"], local_dem):
        out = tmp_path / "out"
        done = cli("segment", dem, "-o", out, "-q", "--format", fmt)
        assert done.returncode != 0, (dem, done.stdout)
        errors = [l for l in done.stderr.splitlines() if "warning" not in l]
        assert len(errors) == 1 and fmt in errors[0] and "GPKG" in errors[0], done.stderr
        assert not out.exists()


def test_kml_on_earth_is_wgs84(cli, tmp_path):
    from osgeo import ogr

    from conftest import SOURCE_DIR

    srtm = SOURCE_DIR / "tests" / "data" / "earth" / "bigtujunga_srtm30m_utm11.tif"
    assert srtm.exists(), srtm
    out = tmp_path / "out"
    done = cli("segment", srtm, "-o", out, "-q", "--format", "KML")
    assert done.returncode == 0, done.stderr
    ds = ogr.Open(str(out / "regions.kml"))
    layer = ds.GetLayer(0)
    xmin, xmax, ymin, ymax = layer.GetExtent()
    # The San Gabriel Mountains in degrees, not UTM metres.
    assert -119 < xmin < xmax < -117 and 33 < ymin < ymax < 35


def test_labels_tif_colours_in_rasterio_and_qgis_style(moon_out):
    import rasterio  # installed by the set-up: a missing client fails
    import xml.etree.ElementTree as ET

    data = json.loads((moon_out / "adjacency.json").read_text())
    fills = {n["id"]: n["fill"] for n in data["nodes"]}
    with rasterio.open(moon_out / "labels.tif") as src:
        assert src.dtypes[0] == "uint16"
        colormap = src.colormap(1)
        labels = src.read(1)
    assert int(labels.max()) == len(fills)
    assert colormap[0][3] == 0  # NoData transparent
    for rid, fill in fills.items():
        assert "#%02x%02x%02x" % colormap[rid][:3] == fill
        assert colormap[rid][3] == 255
    # The QGIS style QGIS loads with labels.tif: a paletted renderer in the same colours.
    style = ET.parse(moon_out / "labels.qml").getroot()
    renderer = style.find("pipe/rasterrenderer")
    assert renderer.get("type") == "paletted" and renderer.get("band") == "1"
    entries = renderer.findall("colorPalette/paletteEntry")
    assert {int(e.get("value")): e.get("color") for e in entries} == fills
    names = {n["id"]: n["landform"] for n in data["nodes"]}
    assert all(e.get("label") == f"{e.get('value')} {names[int(e.get('value'))]}" for e in entries)


def test_labels_tif_attribute_table_read_by_gdal(moon_out):
    from osgeo import gdal

    ds = gdal.Open(str(moon_out / "labels.tif"))
    band = ds.GetRasterBand(1)
    rat = band.GetDefaultRAT()
    assert rat is not None and rat.GetRowCount() == int(band.ComputeRasterMinMax()[1])
    assert band.GetColorTable() is not None


def test_sweep_labels_have_an_attribute_table_per_band(cli, moon, tmp_path):
    from osgeo import gdal

    out = tmp_path / "sweep"
    done = cli("sweep", moon, "-o", out, "-q", "--area-ratios", "0.25,1")
    assert done.returncode == 0, done.stderr
    ds = gdal.Open(str(out / "labels.tif"))
    assert ds.RasterCount == 2
    counts = []
    for b in (1, 2):
        band = ds.GetRasterBand(b)
        rat = band.GetDefaultRAT()
        assert rat is not None, b
        names = [rat.GetNameOfCol(c) for c in range(rat.GetColumnCount())]
        assert {"id", "landform", "Red", "Green", "Blue", "Alpha"} <= set(names)
        assert rat.GetRowCount() == int(band.ReadAsArray().max())
        counts.append(rat.GetRowCount())
    assert counts[0] > counts[1]  # a finer scale has more regions


def test_gpkg_layer_style_row(cli, moon, tmp_path):
    from osgeo import ogr
    import xml.etree.ElementTree as ET

    out = tmp_path / "out"
    assert cli("segment", moon, "-o", out, "-q", "--format", "GPKG").returncode == 0
    ds = ogr.Open(str(out / "regions.gpkg"))
    styles = ds.GetLayerByName("layer_styles")
    # The default (each region in its colour) and one by landform class.
    assert styles is not None and styles.GetFeatureCount() == 2
    rows = {f.GetField("styleName"): f for f in styles}
    assert set(rows) == {"regions", "regions by landform"}
    row = rows["regions"]
    assert row.GetField("f_table_name") == "regions" and row.GetField("useAsDefault") == 1
    landform_row = rows["regions by landform"]
    assert landform_row.GetField("f_table_name") == "regions"
    assert landform_row.GetField("useAsDefault") == 0
    regions = ds.GetLayerByName("regions")
    assert row.GetField("f_geometry_column") == regions.GetGeometryColumn()
    qml = ET.fromstring(row.GetField("styleQML").split("\n", 1)[1])
    renderer = qml.find("renderer-v2")
    assert renderer.get("type") == "categorizedSymbol" and renderer.get("attr") == "id"
    categories = renderer.findall("categories/category")
    assert len(categories) == regions.GetFeatureCount()
    fills = {f.GetField("id"): f.GetField("fill") for f in regions}
    symbols = {s.get("name"): s for s in renderer.findall("symbols/symbol")}
    for c in categories:
        rgb = symbols[c.get("symbol")].find("layer/Option/Option[@name='color']").get("value")
        r, g, b, _ = map(int, rgb.split(","))
        assert "#%02x%02x%02x" % (r, g, b) == fills[int(c.get("value"))]
    # By landform: one category per class, every region's class among them, cups blue and
    # caps red (the preview's colours).
    qml = ET.fromstring(landform_row.GetField("styleQML").split("\n", 1)[1])
    renderer = qml.find("renderer-v2")
    assert renderer.get("type") == "categorizedSymbol" and renderer.get("attr") == "landform"
    symbols = {s.get("name"): s for s in renderer.findall("symbols/symbol")}
    colour = {}
    for c in renderer.findall("categories/category"):
        rgb = symbols[c.get("symbol")].find("layer/Option/Option[@name='color']").get("value")
        colour[c.get("value")] = tuple(map(int, rgb.split(",")))[:3]
    assert list(colour) == ["cup", "trough", "rut", "saddle rut", "saddle", "saddle ridge",
                            "ridge", "dome", "cap", "unknown"]
    assert len(set(colour.values())) == len(colour)
    assert colour["cup"][2] > colour["cup"][0] and colour["cap"][0] > colour["cap"][2]
    regions.ResetReading()
    assert {f.GetField("landform") for f in regions} <= set(colour)


@pytest.mark.parametrize("name,geographic,projected", [
    ("vesta", "200000400", None),      # equirectangular at lon 150, lat_ts -30: no code of its own
    ("moon4c", "30100", "30115"),      # equirectangular, clon = 180
])
def test_planetary_outputs_carry_the_iau_2015_crs(cli, tmp_path, name, geographic, projected):
    import geopandas as gpd  # installed by the set-up: a missing client fails
    import pyproj  # installed by the set-up: a missing client fails
    import numpy as np  # installed by the set-up: a missing client fails
    from osgeo import gdal, ogr

    from conftest import SAMPLE_FILES

    out = tmp_path / "out"
    assert cli("segment", SAMPLE_FILES[name], "-o", out, "-q").returncode == 0
    gpkg = tmp_path / "gpkg"
    assert cli("segment", SAMPLE_FILES[name], "-o", gpkg, "-q", "--format", "GPKG").returncode == 0
    # GeoJSON: the body's IAU_2015 geographic CRS by its code.
    crs_member = json.loads((out / "regions.geojson").read_text())["crs"]["properties"]["name"]
    assert crs_member == f"urn:ogc:def:crs:IAU_2015::{geographic}"
    for file in ("regions.geojson", "adjacency.geojson"):
        ds = ogr.Open(str(out / file))
        srs = ds.GetLayer(0).GetSpatialRef()
        # OGR names the authority of the code "IAU" (WKT1's form of IAU_2015).
        assert srs.GetAuthorityName(None) in ("IAU", "IAU_2015"), file
        assert srs.GetAuthorityCode(None) == geographic, file
        # geopandas (through fiona's WKT1) reads the same CRS.
        assert gpd.read_file(out / file).crs.equals(f"IAU_2015:{geographic}", ignore_axis_order=True)
    gdf = gpd.read_file(out / "regions.geojson")
    # GeoPackage: the DEM's projected CRS on the IAU body, with the authority code.
    ds = ogr.Open(str(gpkg / "regions.gpkg"))
    layer = ds.GetLayerByName("regions")
    srs = layer.GetSpatialRef()
    assert srs.GetAuthorityName("GEOGCS") in ("IAU", "IAU_2015")
    assert srs.GetAuthorityCode("GEOGCS") == geographic
    crs = pyproj.CRS(srs.ExportToWkt(["FORMAT=WKT2_2019"]))
    assert crs.geodetic_crs.equals(f"IAU_2015:{geographic}", ignore_axis_order=True)
    if projected:
        assert srs.GetAuthorityName(None) in ("IAU", "IAU_2015")
        assert srs.GetAuthorityCode(None) == projected
        assert crs.equals(f"IAU_2015:{projected}", ignore_axis_order=True)
    # geopandas transforms it to the body's IAU CRS (same body: no refusal).
    if projected:
        lonlat = gpd.read_file(gpkg / "regions.gpkg", layer="regions").to_crs(
            f"IAU_2015:{geographic}")
        assert lonlat.geometry.is_valid.all()
        a = lonlat.total_bounds
    else:
        # Without a code of its own, geopandas 0.12 gets the CRS through fiona's WKT1, which
        # drops the IAU identity PROJ needs to transform: GDAL's WKT2 keeps it.
        to_iau = pyproj.Transformer.from_crs(
            pyproj.CRS(srs.ExportToWkt(["FORMAT=WKT2_2019"])), f"IAU_2015:{geographic}",
            always_xy=True)
        xmin, xmax, ymin, ymax = layer.GetExtent()
        a = np.array(to_iau.transform_bounds(xmin, ymin, xmax, ymax))
        # What docs/outputs.md tells geopandas users: set the CRS from the file's code, then
        # to_crs works (here to the body's equirectangular CRS, clon = 0).
        fixed = gpd.read_file(out / "regions.geojson").set_crs(
            crs_member.replace("urn:ogc:def:crs:IAU_2015::", "IAU_2015:"), allow_override=True)
        eqc = fixed.to_crs(f"IAU_2015:{int(geographic) + 10}")
        assert eqc.geometry.is_valid.all() and np.isfinite(eqc.total_bounds).all()
    b = gdf.total_bounds
    assert abs(a[[1, 3]] - b[[1, 3]]).max() < 1e-6  # latitudes
    assert all(abs((x - y + 180) % 360 - 180) < 1e-6 for x, y in zip(a[[0, 2]], b[[0, 2]]))
    # labels.tif: pyproj identifies the base CRS.
    tif = pyproj.CRS(gdal.Open(str(out / "labels.tif")).GetSpatialRef().ExportToWkt(["FORMAT=WKT2_2019"]))
    # GeoTIFF's keys hold no IAU code: the names and sphere are kept, the same CRS.
    assert tif.geodetic_crs.equals(f"IAU_2015:{geographic}", ignore_axis_order=True)


@pytest.mark.parametrize("crs,pixel,lonlat,projected", [
    # Mars: an equirectangular DEM in PROJ's IAU_2015 code (clon 0), 2 km pixels.
    ("IAU_2015:49910", 2000.0, ("IAU_2015", "49900"), ("IAU_2015", "49910")),
    # Earth: UTM zone 11 N on WGS 84, 30 m pixels; GeoJSON is RFC 7946 (WGS 84 lon/lat).
    ("EPSG:32611", 30.0, ("EPSG", "4326"), ("EPSG", "32611")),
])
def test_mars_and_earth_crs_identified_with_an_authority(cli, tmp_path, crs, pixel, lonlat,
                                                         projected):
    import geopandas as gpd  # installed by the set-up: a missing client fails
    import pyproj  # installed by the set-up: a missing client fails
    from osgeo import gdal, ogr

    dem = write_raster(tmp_path / "dem.tif", hills() * 20, "GTiff",
                       (400000.0, pixel, 0.0, 3800000.0, 0.0, -pixel), crs)
    out, gpkg = tmp_path / "out", tmp_path / "gpkg"
    assert cli("segment", dem, "-o", out, "-q").returncode == 0
    assert cli("segment", dem, "-o", gpkg, "-q", "--format", "GPKG").returncode == 0
    # labels.tif and the GeoPackage: PROJ identifies the DEM's CRS by its code (what
    # `projinfo --identify` does; pyproj calls the same proj_identify).
    ds = gdal.Open(str(out / "labels.tif"))
    tif = pyproj.CRS(ds.GetSpatialRef().ExportToWkt(["FORMAT=WKT2_2019"]))
    assert tif.to_authority(min_confidence=70) == projected
    assert tif.geodetic_crs.to_authority(min_confidence=70) == lonlat
    vector = ogr.Open(str(gpkg / "regions.gpkg"))
    srs = vector.GetLayerByName("regions").GetSpatialRef()
    assert (srs.GetAuthorityName(None).replace("IAU", "IAU_2015").replace("_2015_2015", "_2015"),
            srs.GetAuthorityCode(None)) == projected
    # GeoJSON: lon/lat on the body; geopandas reads the body's CRS (through fiona's WKT1,
    # without the code on Mars, hence `equals`) and transforms it to the projected one, where
    # the polygons cover the DEM's footprint.
    regions = gpd.read_file(out / "regions.geojson")
    assert regions.crs.equals(":".join(lonlat), ignore_axis_order=True)
    assert regions.geometry.is_valid.all()
    xmin, ymin, xmax, ymax = regions.to_crs(":".join(projected)).total_bounds
    assert abs(xmin - 400000) < pixel and abs(ymax - 3800000) < pixel
    assert abs(xmax - (400000 + 96 * pixel)) < pixel and abs(ymin - (3800000 - 96 * pixel)) < pixel
    # The GeoPackage through geopandas (fiona hands it WKT1, which loses the code of the
    # Martian CRS but not its body): to lon/lat on the body, the GeoJSON's footprint.
    polygons = gpd.read_file(gpkg / "regions.gpkg", layer="regions")
    bounds = polygons.to_crs(":".join(lonlat)).total_bounds
    assert abs(bounds - regions.total_bounds).max() < 1e-6
