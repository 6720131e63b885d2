"""labels.tif with its labels.qml, rendered headless by QGIS (PyQGIS from Debian's python3-qgis,
QT_QPA_PLATFORM=offscreen): each region is drawn in the colour the style gives its id."""

import os
import pathlib
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from osgeo import gdal

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]
VESTA = SOURCE_DIR / "examples" / "data" / "vesta_hamo_tile.lbl"

gdal.UseExceptions()

# Loads the raster with its default style (the .qml beside it), renders it at its own size
# divided by argv[3] on white and saves a PNG; exits without tearing QGIS down (which may crash
# on the way out).
RENDER = r"""
import os, sys
from qgis.core import QgsApplication, QgsMapRendererSequentialJob, QgsMapSettings, QgsRasterLayer
from qgis.PyQt.QtCore import QSize
from qgis.PyQt.QtGui import QColor
app = QgsApplication([], False)
app.initQgis()
layer = QgsRasterLayer(sys.argv[1], "labels")
assert layer.isValid(), "QGIS cannot open " + sys.argv[1]
message, ok = layer.loadDefaultStyle()
assert ok, message
print(layer.renderer().type())
settings = QgsMapSettings()
settings.setLayers([layer])
settings.setDestinationCrs(layer.crs())
settings.setExtent(layer.extent())
shrink = int(sys.argv[3])
settings.setOutputSize(QSize(layer.width() // shrink, layer.height() // shrink))
settings.setBackgroundColor(QColor(255, 255, 255))
job = QgsMapRendererSequentialJob(settings)
job.start()
job.waitForFinished()
assert job.renderedImage().save(sys.argv[2])
sys.stdout.flush()
os._exit(0)
"""


def render(tif, png, tmp_path, shrink=1):
    runtime = tmp_path / "runtime"
    runtime.mkdir(mode=0o700, exist_ok=True)
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", XDG_RUNTIME_DIR=str(runtime),
               QGIS_CUSTOM_CONFIG_PATH=str(tmp_path / "config"), GDAL_PAM_ENABLED="YES")
    done = subprocess.run(["/usr/bin/python3", "-c", RENDER, str(tif), str(png), str(shrink)],
                          env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout.split()[-1]


def segment_vesta(tmp_path):
    out = tmp_path / "vesta"
    done = subprocess.run([os.environ["TERRAIN_CLI"], "segment", str(VESTA), "-o", str(out), "-q"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    palette = {}
    for entry in ET.parse(out / "labels.qml").getroot().iter("paletteEntry"):
        c = entry.get("color")
        palette[int(entry.get("value"))] = (int(c[1:3], 16), int(c[3:5], 16), int(c[5:7], 16))
    return out, palette


def test_labels_render_in_their_style_colours(tmp_path):
    out, palette = segment_vesta(tmp_path)
    png = tmp_path / "render.png"
    assert render(out / "labels.tif", png, tmp_path) == "paletted"

    labels = gdal.Open(str(out / "labels.tif")).ReadAsArray()
    image = gdal.Open(str(png)).ReadAsArray()[:3].transpose(1, 2, 0)
    assert image.shape[:2] == labels.shape
    assert len(palette) == len(np.unique(labels[labels > 0]))
    # Away from region boundaries each pixel has its region's colour.
    rows, cols = labels.shape
    checked = 0
    for r in range(2, rows - 2, 7):
        for c in range(2, cols - 2, 7):
            block = labels[r - 1:r + 2, c - 1:c + 2]
            if labels[r, c] == 0 or (block != labels[r, c]).any():
                continue
            assert tuple(image[r, c]) == palette[labels[r, c]], (r, c, labels[r, c])
            checked += 1
    assert checked > 2000
    # Many colours, not a grey ramp.
    colours = {tuple(p) for p in image.reshape(-1, 3)[::97]}
    assert len(colours) > 20
    assert sum(1 for p in colours if len(set(p)) > 1) >= len(colours) - 1


def test_overviews_render_in_the_regions_colours(tmp_path):
    # Drawn at a quarter of its size QGIS reads the 128 x 128 overview, whose directory has no
    # colour table (plain ids): the style's palette colours it as the full grid.
    out, palette = segment_vesta(tmp_path)
    png = tmp_path / "quarter.png"
    assert render(out / "labels.tif", png, tmp_path, shrink=4) == "paletted"
    dataset = gdal.Open(str(out / "labels.tif"))
    overview = dataset.GetRasterBand(1).GetOverview(1)
    assert overview.GetColorTable() is None
    ids = overview.ReadAsArray()
    image = gdal.Open(str(png)).ReadAsArray()[:3].transpose(1, 2, 0)
    assert image.shape[:2] == ids.shape == (128, 128)
    checked = 0
    for r in range(1, 127):
        for c in range(1, 127):
            if ids[r, c] == 0 or (ids[r - 1:r + 2, c - 1:c + 2] != ids[r, c]).any():
                continue
            assert tuple(image[r, c]) == palette[ids[r, c]], (r, c, ids[r, c])
            checked += 1
    assert checked > 2000
