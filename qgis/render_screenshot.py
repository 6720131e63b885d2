"""Renders what the provider's segment algorithm loads into QGIS (the regions with their
styles over the shape index) to a PNG, headless: the picture in docs/qgis.md.

    QT_QPA_PLATFORM=offscreen /usr/bin/python3 qgis/render_screenshot.py OUTDIR PNG

OUTDIR is a folder written by "Segment DEM into landform regions" (or `terrain segment`)."""

import os
import sys

from qgis.core import (
    QgsApplication,
    QgsMapRendererParallelJob,
    QgsMapSettings,
    QgsRasterLayer,
    QgsVectorLayer,
)
from qgis.PyQt.QtCore import QSize
from qgis.PyQt.QtGui import QColor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def main(outdir, png):
    app = QgsApplication([], False)
    app.initQgis()
    from terrain_provider.algorithms import LabelStyle, RegionStyle

    regions = QgsVectorLayer(os.path.join(outdir, "regions.geojson"), "regions", "ogr")
    labels = QgsRasterLayer(os.path.join(outdir, "labels.tif"), "labels")
    assert regions.isValid() and labels.isValid()
    RegionStyle().postProcessLayer(regions, None, None)
    LabelStyle(os.path.join(outdir, "regions.geojson")).postProcessLayer(labels, None, None)
    settings = QgsMapSettings()
    settings.setLayers([regions, labels])
    settings.setDestinationCrs(labels.crs())
    settings.setExtent(labels.extent())
    settings.setOutputSize(QSize(800, 800))
    settings.setBackgroundColor(QColor("white"))
    job = QgsMapRendererParallelJob(settings)
    job.start()
    job.waitForFinished()
    job.renderedImage().save(png, "png")
    app.exitQgis()


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
