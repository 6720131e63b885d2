"""The GeoPackage's two styles as QGIS 3.22 (PyQGIS, headless) sees them: the default colours
each region, the second (from the layer_styles table) colours regions by landform class."""

import os
import pathlib
import subprocess

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]
VESTA = SOURCE_DIR / "examples" / "data" / "vesta_hamo_tile.lbl"

# Loads the layer (QGIS applies the default style from layer_styles), then the landform style
# by its database id, and prints what each renderer is.
SHOW = r"""
import os, sys
from qgis.core import QgsApplication, QgsVectorLayer
app = QgsApplication([], False)
app.initQgis()
layer = QgsVectorLayer(sys.argv[1] + "|layername=regions", "regions", "ogr")
assert layer.isValid()
r = layer.renderer()
print("default", r.type(), r.classAttribute(), len(r.categories()), layer.featureCount())
count, ids, names, descriptions, message = layer.listStylesInDatabase()
print("styles", "|".join(sorted(n.replace(" ", "_") for n in names)))
qml, message = layer.getStyleFromDatabase(ids[names.index("regions by landform")])
from qgis.PyQt.QtXml import QDomDocument
doc = QDomDocument()
doc.setContent(qml)
ok, message = layer.importNamedStyle(doc)
assert ok, message
r = layer.renderer()
print("landform", r.type(), r.classAttribute(), ",".join(c.value() for c in r.categories()))
sys.stdout.flush()
os._exit(0)
"""


def test_geopackage_styles_in_qgis(tmp_path):
    out = tmp_path / "out"
    done = subprocess.run([os.environ["TERRAIN_CLI"], "segment", str(VESTA), "-o", str(out), "-q",
                           "--format", "GPKG"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    runtime = tmp_path / "runtime"
    runtime.mkdir(mode=0o700)
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", XDG_RUNTIME_DIR=str(runtime),
               QGIS_CUSTOM_CONFIG_PATH=str(tmp_path / "config"))
    shown = subprocess.run(["/usr/bin/python3", "-c", SHOW, str(out / "regions.gpkg")], env=env,
                           capture_output=True, text=True, timeout=120)
    assert shown.returncode == 0, shown.stderr
    lines = {line.split(" ", 1)[0]: line.split(" ")[1:] for line in shown.stdout.splitlines()}
    kind, attribute, categories, features = lines["default"]
    assert (kind, attribute) == ("categorizedSymbol", "id")
    assert int(categories) == int(features) > 50
    assert lines["styles"] == ["regions|regions_by_landform"]
    kind, attribute, values = " ".join(lines["landform"]).split(" ", 2)  # names hold spaces
    assert (kind, attribute) == ("categorizedSymbol", "landform")
    assert values.split(",") == ["cup", "trough", "rut", "saddle rut", "saddle", "saddle ridge",
                                 "ridge", "dome", "cap", "unknown"]
