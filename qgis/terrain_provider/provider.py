"""The terrain Processing provider: its three algorithms."""

import os

from qgis.core import QgsProcessingProvider
from qgis.PyQt.QtGui import QIcon

from . import backend
from .algorithms import SegmentAlgorithm, ShapeIndexAlgorithm, SweepAlgorithm


class TerrainProvider(QgsProcessingProvider):
    def id(self):
        return "terrain"

    def name(self):
        return "terrain"

    def longName(self):  # noqa: N802
        return "terrain: landform regions with Reeb graphs (" + backend.describe() + ")"

    def icon(self):
        return QIcon(os.path.join(os.path.dirname(__file__), "icon.svg"))

    def loadAlgorithms(self):  # noqa: N802
        for algorithm in (SegmentAlgorithm(), SweepAlgorithm(), ShapeIndexAlgorithm()):
            self.addAlgorithm(algorithm)
