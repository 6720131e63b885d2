"""Registers the terrain Processing provider (also when QGIS runs without its interface, as
qgis_process does: initProcessing is called then)."""

from qgis.core import QgsApplication


class TerrainPlugin:
    def __init__(self, iface):
        self.iface = iface
        self.provider = None

    def initProcessing(self):  # noqa: N802
        from .provider import TerrainProvider

        self.provider = TerrainProvider()
        QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self):  # noqa: N802
        self.initProcessing()

    def unload(self):
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
