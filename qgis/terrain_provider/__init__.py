"""terrain's QGIS plugin: a Processing provider (docs/qgis.md)."""


def classFactory(iface):  # noqa: N802 (QGIS's name)
    from .plugin import TerrainPlugin

    return TerrainPlugin(iface)
