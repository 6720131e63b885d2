"""The outputs' CRS as QGIS 3.22 (PyQGIS, headless) names it: a GeoPackage of a planetary DEM
carries its IAU_2015 code in the WKT2 column (gpkg_crs_wkt), which QGIS reads; WKT1 cannot
hold the code's version and QGIS 3.22 then finds no CRS at all."""

import os
import pathlib
import sqlite3
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]
DATA = SOURCE_DIR / "examples" / "data"

# Prints, for each file, whether QGIS finds a valid CRS, its authority id and its description.
PRINT_CRS = r"""
import os, sys
from qgis.core import QgsApplication, QgsRasterLayer, QgsVectorLayer
app = QgsApplication([], False)
app.initQgis()
for path in sys.argv[1:]:
    layer = QgsRasterLayer(path, "l") if path.endswith(".tif") else QgsVectorLayer(path, "v", "ogr")
    assert layer.isValid(), "QGIS cannot open " + path
    crs = layer.crs()
    print("|".join([path, str(crs.isValid()), crs.authid(), crs.description()]))
sys.stdout.flush()
os._exit(0)
"""


def qgis_crs(tmp_path, *paths):
    runtime = tmp_path / "runtime"
    runtime.mkdir(mode=0o700, exist_ok=True)
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", XDG_RUNTIME_DIR=str(runtime),
               QGIS_CUSTOM_CONFIG_PATH=str(tmp_path / "config"))
    done = subprocess.run(["/usr/bin/python3", "-c", PRINT_CRS, *map(str, paths)], env=env,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    out = {}
    for line in done.stdout.splitlines():
        path, valid, authid, description = line.split("|")
        out[pathlib.Path(path).name] = (valid == "True", authid, description)
    return out


def mars_dem(path):
    """A synthetic Martian DEM in IAU_2015:49910 (equirectangular, clon 0), 2 km pixels."""
    import numpy as np
    from osgeo import gdal, osr

    gdal.UseExceptions()
    y, x = np.mgrid[0:64, 0:64].astype(float)
    z = 800 * np.exp(-((x - 20) ** 2 + (y - 30) ** 2) / 120) - 500 * np.exp(
        -((x - 45) ** 2 + (y - 20) ** 2) / 90)
    ds = gdal.GetDriverByName("GTiff").Create(str(path), 64, 64, 1, gdal.GDT_Float32)
    srs = osr.SpatialReference()
    srs.SetFromUserInput("IAU_2015:49910")
    ds.SetProjection(srs.ExportToWkt(["FORMAT=WKT2_2019"]))
    ds.SetGeoTransform((400000.0, 2000.0, 0.0, 3800000.0, 0.0, -2000.0))
    ds.GetRasterBand(1).WriteArray(z)
    ds = None
    return path


@pytest.mark.parametrize("dem,geographic,projected", [
    ("moon_ldem4_copernicus.tif", "30100", "30115"),  # equirectangular, clon = 180
    ("vesta_hamo_tile.lbl", "200000400", None),       # its projection has no code of its own
    ("mars", "49900", "49910"),                       # made here
])
def test_qgis_names_the_geopackage_crs(tmp_path, dem, geographic, projected):
    out = tmp_path / "out"
    source = mars_dem(tmp_path / "mars.tif") if dem == "mars" else DATA / dem
    done = subprocess.run([os.environ["TERRAIN_CLI"], "segment", str(source), "-o", str(out),
                           "-q", "--format", "GPKG"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    gpkg = out / "regions.gpkg"
    # The WKT2 column, registered as the gpkg_crs_wkt extension, holds the code with its
    # version (WKT1's AUTHORITY cannot).
    with sqlite3.connect(gpkg) as db:
        assert db.execute("SELECT count(*) FROM gpkg_extensions WHERE table_name = "
                          "'gpkg_spatial_ref_sys' AND column_name = 'definition_12_063' AND "
                          "extension_name = 'gpkg_crs_wkt'").fetchone()[0] == 1
        srs_id, = db.execute("SELECT srs_id FROM gpkg_geometry_columns "
                             "WHERE table_name = 'regions'").fetchone()
        wkt2, = db.execute("SELECT definition_12_063 FROM gpkg_spatial_ref_sys "
                           "WHERE srs_id = ?", (srs_id,)).fetchone()
        assert f'ID["IAU",{projected or geographic},2015]' in wkt2
        # Every defined SRS row has its WKT2.
        for definition, wkt in db.execute("SELECT definition, definition_12_063 "
                                          "FROM gpkg_spatial_ref_sys"):
            assert (definition == "undefined") == (wkt == "undefined")
    crs = qgis_crs(tmp_path, gpkg, out / "labels.tif")
    valid, authid, description = crs["regions.gpkg"]
    assert valid, description
    if projected:
        assert authid == f"IAU_2015:{projected}"
        # GeoTIFF keys hold no IAU code, but QGIS identifies the same CRS from labels.tif.
        assert crs["labels.tif"][:2] == (True, f"IAU_2015:{projected}")
    else:
        # A CRS of its own (no code) that QGIS holds as a custom CRS on Vesta's sphere.
        assert authid == "" and crs["labels.tif"][0]
