"""The algorithms: Segment DEM into landform regions, Multi-scale sweep, Shape index."""

import os

from qgis.core import (
    QgsColorRampShader,
    QgsFillSymbol,
    QgsPalettedRasterRenderer,
    QgsProcessing,
    QgsProcessingAlgorithm,
    QgsProcessingContext,
    QgsProcessingException,
    QgsProcessingLayerPostProcessorInterface,
    QgsProcessingOutputFile,
    QgsProcessingOutputNumber,
    QgsProcessingOutputRasterLayer,
    QgsProcessingOutputVectorLayer,
    QgsProcessingParameterBand,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFolderDestination,
    QgsProcessingParameterNumber,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterRasterLayer,
    QgsProcessingParameterString,
    QgsProperty,
    QgsRasterShader,
    QgsSingleBandPseudoColorRenderer,
    QgsStyle,
    QgsSymbolLayer,
    QgsVectorLayer,
)
from qgis.PyQt.QtGui import QColor

from . import backend

FIELDS = ["shape-index", "sdf", "height"]
COSTS = ["auto", "graph", "standard"]
WINDOWS = ["disk", "ball"]
# Landforms at their own scale (terrain segment with no scale option: docs/segment.md), or
# the paper's single scale set by the options that follow.
SCALES = ["landforms at their own scale (automatic)",
          "single scale (rings or radius, persistence, area ratio)"]


def region_colours(regions_path, layer=None):
    """{region id: QColor} from the `fill` attribute of the regions file (the colours of
    preview.png)."""
    uri = regions_path if layer is None else f"{regions_path}|layername={layer}"
    vl = QgsVectorLayer(uri, "regions", "ogr")
    colours = {}
    if vl.isValid() and "fill" in vl.fields().names():
        for f in vl.getFeatures():
            colours[int(f["id"])] = QColor(str(f["fill"]))
    return colours


class RegionStyle(QgsProcessingLayerPostProcessorInterface):
    """Region polygons filled with their `fill` colour, half transparent, dark outlines."""

    def postProcessLayer(self, layer, context, feedback):  # noqa: N802
        if not isinstance(layer, QgsVectorLayer):
            return
        symbol = QgsFillSymbol.createSimple(
            {"color": "128,128,128,160", "outline_color": "35,35,35", "outline_width": "0.2"})
        if "fill" in layer.fields().names():
            symbol.symbolLayer(0).setDataDefinedProperty(
                QgsSymbolLayer.PropertyFillColor,
                QgsProperty.fromExpression("set_color_part(\"fill\", 'alpha', 170)"))
        layer.renderer().setSymbol(symbol)
        layer.triggerRepaint()


class LabelStyle(QgsProcessingLayerPostProcessorInterface):
    """The label raster paletted with the regions' colours (0, NoData, transparent)."""

    def __init__(self, regions_path, layer=None):
        super().__init__()
        self.regions_path = regions_path
        self.layer = layer

    def postProcessLayer(self, layer, context, feedback):  # noqa: N802
        colours = region_colours(self.regions_path, self.layer)
        if not colours:
            return
        classes = [QgsPalettedRasterRenderer.Class(rid, colour, str(rid))
                   for rid, colour in sorted(colours.items())]
        renderer = QgsPalettedRasterRenderer(layer.dataProvider(), 1, classes)
        layer.setRenderer(renderer)
        layer.triggerRepaint()


class ShapeIndexStyle(QgsProcessingLayerPostProcessorInterface):
    """Shape index 0 (cup, blue) .. 50 (saddle) .. 100 (cap, red)."""

    def postProcessLayer(self, layer, context, feedback):  # noqa: N802
        ramp = QgsStyle.defaultStyle().colorRamp("RdBu")
        shader_fn = QgsColorRampShader(0, 100)
        if ramp is not None:
            ramp.invert()
            shader_fn.setSourceColorRamp(ramp)
        shader_fn.setColorRampType(QgsColorRampShader.Interpolated)
        shader_fn.classifyColorRamp(9, -1)
        shader = QgsRasterShader()
        shader.setRasterShaderFunction(shader_fn)
        renderer = QgsSingleBandPseudoColorRenderer(layer.dataProvider(), 1, shader)
        renderer.setClassificationMin(0)
        renderer.setClassificationMax(100)
        layer.setRenderer(renderer)
        layer.triggerRepaint()


def source_path(algorithm, parameters, context):
    layer = algorithm.parameterAsRasterLayer(parameters, "INPUT", context)
    if layer is None:
        raise QgsProcessingException("INPUT: no raster layer")
    if layer.providerType() != "gdal":
        raise QgsProcessingException("INPUT must be a raster file GDAL reads, not a "
                                     + layer.providerType() + " layer")
    return layer.source().split("|")[0]


class _Base(QgsProcessingAlgorithm):
    _post = []  # post-processors must outlive processAlgorithm

    def group(self):
        return ""

    def groupId(self):  # noqa: N802
        return ""

    def createInstance(self):  # noqa: N802
        return type(self)()

    def add_input(self):
        self.addParameter(QgsProcessingParameterRasterLayer("INPUT", "DEM"))
        self.addParameter(QgsProcessingParameterBand("BAND", "Band", 1, "INPUT", optional=True))

    def add_segment_options(self, area_ratio=True):
        if area_ratio:
            self.addParameter(QgsProcessingParameterEnum(
                "SCALE", "Scale", SCALES, defaultValue=0))
        self.addParameter(QgsProcessingParameterEnum("FIELD", "Field", FIELDS, defaultValue=0))
        self.addParameter(QgsProcessingParameterBoolean(
            "AUTO_RADIUS", "Shape index: radius chosen per pixel (auto, DEMs)", False))
        self.addParameter(QgsProcessingParameterNumber(
            "RINGS", "Shape index: rings (mesh edges)", QgsProcessingParameterNumber.Integer, 2,
            minValue=1))
        self.addParameter(QgsProcessingParameterNumber(
            "RADIUS", "Shape index: radius in metres (0: use rings)",
            QgsProcessingParameterNumber.Double, 0, minValue=0))
        self.addParameter(QgsProcessingParameterEnum(
            "WINDOW", "Shape index: window of the radius", WINDOWS, defaultValue=0))
        self.addParameter(QgsProcessingParameterNumber(
            "PERSISTENCE", "Persistence (field units)", QgsProcessingParameterNumber.Double, 10,
            minValue=0))
        if area_ratio:
            self.addParameter(QgsProcessingParameterNumber(
                "AREA_RATIO", "Area ratio (percent of the surface)",
                QgsProcessingParameterNumber.Double, 0.5, minValue=0, maxValue=100))
        self.addParameter(QgsProcessingParameterEnum("COST", "Cost", COSTS, defaultValue=0))
        self.addParameter(QgsProcessingParameterNumber(
            "SADDLE_PENALTY", "Saddle penalty", QgsProcessingParameterNumber.Double, 20,
            minValue=0))

    def segment_options(self, parameters, context, area_ratio=True):
        options = {
            "band": self.parameterAsInt(parameters, "BAND", context) or 1,
            "field": FIELDS[self.parameterAsEnum(parameters, "FIELD", context)],
            "rings": self.parameterAsInt(parameters, "RINGS", context),
            "persistence": self.parameterAsDouble(parameters, "PERSISTENCE", context),
            "cost": COSTS[self.parameterAsEnum(parameters, "COST", context)],
            "saddle_penalty": self.parameterAsDouble(parameters, "SADDLE_PENALTY", context),
        }
        if area_ratio and self.parameterAsEnum(parameters, "SCALE", context) == 0:
            # Landforms at their own scale: no scale option, as `terrain segment` with none.
            for name in ("rings", "persistence"):
                del options[name]
            return options
        radius = self.parameterAsDouble(parameters, "RADIUS", context)
        if self.parameterAsBool(parameters, "AUTO_RADIUS", context):
            del options["rings"]
            options["radius"] = "auto"
        elif radius > 0:  # instead of rings (giving both is refused)
            del options["rings"]
            options["radius"] = radius
            options["window"] = WINDOWS[self.parameterAsEnum(parameters, "WINDOW", context)]
        if area_ratio:
            options["area_ratio"] = self.parameterAsDouble(parameters, "AREA_RATIO", context)
        return options

    def load(self, context, path, name, output, post):
        details = QgsProcessingContext.LayerDetails(name, context.project(), output)
        if post is not None:
            _Base._post.append(post)
            details.setPostProcessor(post)
        context.addLayerToLoadOnCompletion(path, details)


class SegmentAlgorithm(_Base):
    def name(self):
        return "segment"

    def displayName(self):  # noqa: N802
        return "Segment DEM into landform regions"

    def shortHelpString(self):  # noqa: N802
        return ("Segments the DEM into landform regions: the shape index field on the DEM's "
                "mesh, its Reeb graph simplified by persistence and area ratio, and regions "
                "grown from its extrema (terrain segment). Writes labels.tif, "
                "regions.geojson, adjacency.json/.graphml/.geojson, preview.png and run.json "
                "into the output folder and loads the regions and labels.")

    def initAlgorithm(self, config=None):  # noqa: N802
        self.add_input()
        self.add_segment_options()
        self.addParameter(QgsProcessingParameterFolderDestination("OUTPUT", "Output folder"))
        self.addOutput(QgsProcessingOutputRasterLayer("LABELS", "Region labels"))
        self.addOutput(QgsProcessingOutputVectorLayer("REGIONS", "Regions",
                                                      QgsProcessing.TypeVectorPolygon))
        self.addOutput(QgsProcessingOutputFile("ADJACENCY", "Adjacency graph (GraphML)"))
        self.addOutput(QgsProcessingOutputNumber("REGION_COUNT", "Number of regions"))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        path = source_path(self, parameters, context)
        options = self.segment_options(parameters, context)
        outdir = self.parameterAsString(parameters, "OUTPUT", context)
        terrain = backend.module()
        if terrain is not None:
            feedback.pushInfo("terrain " + terrain.__version__ + " (Python module)")
            try:
                result = terrain.segment(path, progress=backend.progress_callback(feedback, 0, 90),
                                         **options)
                result.write(outdir, overwrite=True,
                             progress=backend.progress_callback(feedback, 90, 100))
            except terrain.Error as e:
                raise backend.library_error(e)
            count = result.region_count
            feedback.pushInfo(f"{count} regions")
        else:
            band = options.pop("band")
            out = backend.run_cli(["segment", path, "-o", outdir, "--overwrite", "--band",
                                   str(band), *backend.cli_options(options)], feedback)
            count = int(out.split(": ", 1)[1].split()[0]) if ": " in out else -1
        labels = os.path.join(outdir, "labels.tif")
        regions = os.path.join(outdir, "regions.geojson")
        self.load(context, regions, "regions", "REGIONS", RegionStyle())
        self.load(context, labels, "labels", "LABELS", LabelStyle(regions))
        return {
            "OUTPUT": outdir,
            "LABELS": labels,
            "REGIONS": regions,
            "ADJACENCY": os.path.join(outdir, "adjacency.graphml"),
            "REGION_COUNT": count,
        }


class SweepAlgorithm(_Base):
    def name(self):
        return "sweep"

    def displayName(self):  # noqa: N802
        return "Multi-scale sweep"

    def shortHelpString(self):  # noqa: N802
        return ("Segments the DEM at several area ratios from one field and Reeb graph "
                "(terrain sweep): labels.tif with one band per scale, regions.gpkg with one "
                "layer per scale, lineage.json (how regions merge from scale to scale), "
                "sweep.csv and sweep.png.")

    def initAlgorithm(self, config=None):  # noqa: N802
        self.add_input()
        self.addParameter(QgsProcessingParameterString(
            "AREA_RATIOS", "Area ratios (percent, comma separated)", "0.1,0.25,0.5,1,2"))
        self.add_segment_options(area_ratio=False)
        self.addParameter(QgsProcessingParameterFolderDestination("OUTPUT", "Output folder"))
        self.addOutput(QgsProcessingOutputRasterLayer("LABELS", "Region labels, one band per scale"))
        self.addOutput(QgsProcessingOutputFile("REGIONS", "Regions (GeoPackage)"))
        self.addOutput(QgsProcessingOutputFile("SWEEP", "Regions per scale (CSV)"))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        path = source_path(self, parameters, context)
        options = self.segment_options(parameters, context, area_ratio=False)
        text = self.parameterAsString(parameters, "AREA_RATIOS", context)
        outdir = self.parameterAsString(parameters, "OUTPUT", context)
        terrain = backend.module()
        if terrain is not None:
            try:
                ratios = [float(v) for v in text.split(",")]
            except ValueError:
                raise QgsProcessingException(
                    f"sweep: --area-ratios takes percentages separated by commas, not '{text}'")
            try:
                result = terrain.sweep(path, area_ratios=ratios,
                                       progress=backend.progress_callback(feedback, 0, 80),
                                       **options)
                result.write(outdir, overwrite=True,
                             progress=backend.progress_callback(feedback, 80, 100))
            except terrain.Error as e:
                raise backend.library_error(e)
            names = [f"{s.ratio:g}" for s in result.scales]
            for s in result.scales:
                feedback.pushInfo(f"{s.ratio:g}%: {s.region_count} regions")
        else:
            band = options.pop("band")
            backend.run_cli(["sweep", path, "-o", outdir, "--overwrite", "--band", str(band),
                             "--area-ratios", text, *backend.cli_options(options)], feedback)
            with open(os.path.join(outdir, "sweep.csv"), encoding="utf-8") as f:
                names = [line.split(",")[0] for line in f.read().splitlines()[1:]]
        gpkg = os.path.join(outdir, "regions.gpkg")
        for name in names:
            self.load(context, f"{gpkg}|layername=regions_{name}", f"regions {name}%", "REGIONS",
                      RegionStyle())
        labels = os.path.join(outdir, "labels.tif")
        self.load(context, labels, "labels", "LABELS",
                  LabelStyle(gpkg, f"regions_{names[0]}") if names else None)
        return {"OUTPUT": outdir, "LABELS": labels, "REGIONS": gpkg,
                "SWEEP": os.path.join(outdir, "sweep.csv")}


class ShapeIndexAlgorithm(_Base):
    def name(self):
        return "shapeindex"

    def displayName(self):  # noqa: N802
        return "Shape index"

    def shortHelpString(self):  # noqa: N802
        return ("The shape index x100 of each pixel (0 cup, 25 rut, 50 saddle or plane, "
                "75 ridge, 100 cap), fitted on the DEM's mesh over the vertices within RINGS "
                "mesh edges, or within RADIUS metres when RADIUS > 0 (terrain field): on the "
                "ground (WINDOW disk, any radius at about the cost of 2 rings) or in 3-D "
                "(WINDOW ball).")

    def initAlgorithm(self, config=None):  # noqa: N802
        self.add_input()
        self.addParameter(QgsProcessingParameterNumber(
            "RINGS", "Rings (mesh edges)", QgsProcessingParameterNumber.Integer, 2, minValue=1))
        self.addParameter(QgsProcessingParameterNumber(
            "RADIUS", "Radius in metres (0: use rings)", QgsProcessingParameterNumber.Double, 0,
            minValue=0))
        self.addParameter(QgsProcessingParameterEnum(
            "WINDOW", "Window of the radius", WINDOWS, defaultValue=0))
        self.addParameter(QgsProcessingParameterRasterDestination("OUTPUT", "Shape index"))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        path = source_path(self, parameters, context)
        band = self.parameterAsInt(parameters, "BAND", context) or 1
        rings = self.parameterAsInt(parameters, "RINGS", context)
        radius = self.parameterAsDouble(parameters, "RADIUS", context)
        window = WINDOWS[self.parameterAsEnum(parameters, "WINDOW", context)]
        out = self.parameterAsOutputLayer(parameters, "OUTPUT", context)
        terrain = backend.module()
        if terrain is not None:
            from osgeo import gdal

            try:
                si = terrain.shape_index(path, band=band, rings=rings, radius=radius,
                                         window=window,
                                         progress=backend.progress_callback(feedback, 0, 95))
            except terrain.Error as e:
                raise backend.library_error(e)
            src = gdal.Open(path)
            driver = gdal.GetDriverByName("GTiff")
            ds = driver.Create(out, si.shape[1], si.shape[0], 1, gdal.GDT_Float32,
                               ["COMPRESS=DEFLATE", "TILED=YES"])
            if src.GetGeoTransform(can_return_null=True):
                ds.SetGeoTransform(src.GetGeoTransform())
            ds.SetProjection(src.GetProjection())
            b = ds.GetRasterBand(1)
            b.SetNoDataValue(float("nan"))
            b.SetDescription("shape index x100")
            b.WriteArray(si)
            ds = None
        else:
            shape = (["--radius", str(radius), "--window", window] if radius > 0
                     else ["--rings", str(rings)])
            backend.run_cli(["field", path, "--field", "shape-index", "-o", out, "--overwrite",
                             "--band", str(band), *shape], feedback)
        self.load(context, out, "shape index", "OUTPUT", ShapeIndexStyle())
        return {"OUTPUT": out}
