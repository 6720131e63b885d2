"""terrain: segment planetary DEMs into landform regions with Reeb graphs.

The C++ library as Python calls (docs/python.md)::

    import terrain
    result = terrain.segment("tile.tif", persistence=10, area_ratio=0.5)
    result.labels              # 2-D numpy array on the DEM's grid, as labels.tif
    result.regions             # dict of numpy columns, one row per region
    result.to_geodataframe()   # the region polygons (geopandas)
    result.graph.to_networkx() # the adjacency graph (networkx)

A DEM can be a path, a terrain.Dem (terrain.read_dem), a 2-D numpy array (NaN = NoData)
with its GDAL geotransform and CRS, or an xarray DataArray with its CRS and transform
(rioxarray's .rio), whose results come back as DataArrays on its grid (da.terrain.segment()
once xarray is imported). Long calls release the GIL; `progress` takes a callable
progress(fraction, message) that returns False to cancel. The library's errors raise
terrain.Error with the command line's one-line messages.
"""

import importlib.abc
import os
import sys
import tempfile

import numpy as np

from . import _terrain
from ._terrain import Dem, Error, __version__, page_use

__all__ = [
    "Dem",
    "Error",
    "ReebGraph",
    "RegionGraph",
    "SegmentResult",
    "SweepResult",
    "page_use",
    "read_dem",
    "reeb_graph",
    "segment",
    "shape_index",
    "sweep",
]

# The options of `terrain segment` (docs/cli.md), as keyword arguments.
_SEGMENT_OPTIONS = (
    "field", "rings", "radius", "radii", "window", "rays", "cone_angle", "postprocess", "allow_open",
    "persistence", "area_ratio", "min_area", "cost", "saddle_penalty", "absorbed",
    "format", "craters",
)
# The options of the calls that read no crater table (sweep, shape_index, reeb_graph).
_OPTIONS_BUT_CRATERS = tuple(o for o in _SEGMENT_OPTIONS if o != "craters")
# The options that set a scale: given none, a DEM takes the landform defaults (radius "auto",
# min_area "auto"; docs/segment.md), as `terrain segment` does.
_SCALE_OPTIONS = ("rings", "radius", "radii", "persistence", "area_ratio", "min_area")
# How the input is read and meshed.
_INPUT_OPTIONS = ("band", "elevation", "nan_nodata", "pixel_size", "frame", "repair",
                  "max_memory")


def read_dem(path, band=1, *, elevation="auto", nan_nodata=False, pixel_size=None):
    """Read one band of any raster GDAL opens into a terrain.Dem.

    Scale and offset are applied and NoData becomes NaN. elevation: "auto" (detected),
    "height" or "radius". nan_nodata: NaN/Inf pixels become holes instead of an error.
    pixel_size: metres per pixel for a raster without geotransform.
    Returns a Dem with .values (2-D float64), .geotransform, .crs (WKT), .body, .elevation.
    Raises terrain.Error when the file is missing or not a DEM.
    """
    return _terrain.read_dem(os.fspath(path), band, elevation, nan_nodata, pixel_size)


def _geotransform(geotransform):
    if geotransform is None:
        return None
    if hasattr(geotransform, "to_gdal"):  # an affine.Affine, as rasterio gives it
        geotransform = geotransform.to_gdal()
    return [float(v) for v in geotransform]


def _crs(crs):
    if crs is None:
        return ""
    if hasattr(crs, "to_wkt"):  # rasterio.crs.CRS, pyproj.CRS, osgeo.osr.SpatialReference
        return crs.to_wkt() if not hasattr(crs, "ExportToWkt") else crs.ExportToWkt()
    if hasattr(crs, "ExportToWkt"):
        return crs.ExportToWkt()
    return str(crs)


def _xarray_support(dem):
    """terrain._xarray when `dem` is an xarray object, else None (xarray is never imported
    here: an object of xarray's exists only once xarray is)."""
    xr = sys.modules.get("xarray")
    if xr is None or not isinstance(dem, (xr.DataArray, xr.Dataset)):
        return None
    from . import _xarray

    return _xarray


def _prepare(dem, geotransform, crs, read):
    """(the native source, the read options left, the Grid of a DataArray or None)."""
    elevation = read.pop("elevation")
    xa = _xarray_support(dem)
    if xa is None:
        source = _source(dem, geotransform, crs, elevation)
        if isinstance(source, str):  # a path: the library reads it with the read options
            read["elevation"] = elevation
        return source, read, None
    if xa.is_dataset(dem):
        raise Error("read: give a DataArray (one variable of the Dataset: ds['name']), not a "
                    "Dataset")
    if geotransform is not None or crs is not None:
        raise Error("read: a DataArray carries its own CRS and transform (.rio.write_crs, "
                    ".rio.write_transform); do not pass geotransform or crs")
    values, transform, wkt, grid = xa.dem_source(dem, read.pop("band", 1))
    return _terrain.dem_from_array(values, transform, wkt, elevation), read, grid


def _on_grid(grid, values, name, nodata, attrs=None):
    """`values` as a DataArray on the input DataArray's grid; as they are for other input."""
    if grid is None or values is None or np.ndim(values) != 2:
        return values
    return grid.wrap(values, name, nodata, attrs)


def _source(dem, geotransform, crs, elevation):
    """A path (str), a Dem, or a Dem made from an array."""
    if isinstance(dem, Dem):
        return dem
    if isinstance(dem, (str, bytes, os.PathLike)):
        return os.fsdecode(dem)
    values = dem
    if isinstance(values, np.ma.MaskedArray):
        values = values.astype(np.float64).filled(np.nan)
    values = np.asarray(values, dtype=np.float64)
    if values.ndim == 3 and values.shape[0] == 1:  # one band as rasterio reads it
        values = values[0]
    return _terrain.dem_from_array(values, _geotransform(geotransform), _crs(crs), elevation)


def _split_options(options, allowed):
    native = _terrain.SegmentOptions()
    read = {}
    if "rings" in options and options.get("radius", 0):
        raise Error("field: give rings or radius, not both")
    if "radii" in options and options.get("radius") != "auto":
        raise Error("field: radii goes with radius=\"auto\"")
    # No scale option: a DEM takes the landform defaults, as on the command line.
    native.landform_defaults = not any(
        options.get(name) is not None for name in _SCALE_OPTIONS)
    if options.get("area_ratio") is not None and options.get("min_area") is not None:
        raise Error("segment: give area_ratio or min_area, not both")
    for name, value in options.items():
        if name in allowed:
            setattr(native, name, value)
        elif name in _INPUT_OPTIONS:
            read[name] = value
        else:
            raise TypeError(f"unknown option '{name}'; the options are: "
                            + ", ".join(allowed + _INPUT_OPTIONS))
    if "elevation" not in read:
        read["elevation"] = "auto"
    return native, read


def _input_path(source):
    return source.source if isinstance(source, Dem) else source


class RegionGraph:
    """The regions' adjacency graph: .nodes (the region table) and .edges, numpy columns.

    Edge columns: a, b (region ids, a < b), boundary_length_m, contrast (|field_mean(a) -
    field_mean(b)|), mesh_edges.
    """

    def __init__(self, nodes, edges):
        self.nodes = nodes
        self.edges = edges

    def __len__(self):
        return len(self.nodes["id"])

    def to_networkx(self):
        """A networkx.Graph: one node per region id with the region's columns as attributes,
        one edge per pair of adjacent regions with the edge's columns."""
        import networkx as nx

        g = nx.Graph()
        names = list(self.nodes)
        for i, rid in enumerate(self.nodes["id"]):
            g.add_node(int(rid), **{k: _scalar(self.nodes[k][i]) for k in names if k != "id"})
        enames = [k for k in self.edges if k not in ("a", "b")]
        for i in range(len(self.edges["a"])):
            g.add_edge(int(self.edges["a"][i]), int(self.edges["b"][i]),
                       **{k: _scalar(self.edges[k][i]) for k in enames})
        return g


def _scalar(v):
    return v.item() if hasattr(v, "item") else v


def _geodataframe(write_polygons, regions):
    import geopandas

    with tempfile.TemporaryDirectory(prefix="terrain-") as tmp:
        path = os.path.join(tmp, "regions.gpkg")
        write_polygons(path)
        gdf = geopandas.read_file(path)
    return gdf


class SegmentResult:
    """What terrain.segment returns.

    labels: the label of each DEM pixel (2-D uint32, 0 = NoData), identical to the command
        line's labels.tif; None for a mesh file (see vertex_labels).
    vertex_labels: the label of each mesh vertex.
    field: the field (shape index x100 by default) on the DEM's grid (NaN = NoData).
    regions: the region table, a dict of numpy columns (id, area_m2, field_mean, landform,
        point_x/y/z, ...; docs/outputs.md).
    graph: the adjacency graph (RegionGraph; .to_networkx()).
    craters: the craters read from the regions, a geopandas.GeoDataFrame of points at their
        centres (docs/craters.md); None for a mesh file or with craters=False.
    field_scale_m: with the radius chosen per pixel (the default on DEMs), each pixel's
        region's field_scale_m (NaN = NoData); None otherwise.
    region_count, critical_before, critical_after, timings, dem.
    For a DataArray input, labels, field and field_scale_m are DataArrays on its grid (its
    x/y coordinates, CRS and transform; NoData 0 for the labels, NaN for the others).
    """

    def __init__(self, native, options, input_path, grid=None):
        self._native = native
        self._options = options
        self._input_path = input_path
        self._grid = grid
        self.regions = native.region_columns
        self.graph = RegionGraph(self.regions, native.edge_columns)

    @property
    def labels(self):
        return _on_grid(self._grid, self._native.labels, "labels", 0)

    @property
    def field(self):
        return _on_grid(self._grid, self._native.field, "field", np.nan,
                        {"field": self._options.field})

    @property
    def field_scale_m(self):
        scale = self.regions.get("field_scale_m")
        labels = self._native.labels
        if scale is None or labels is None:
            return None
        by_label = np.full(int(self.regions["id"].max(initial=0)) + 1, np.nan)
        by_label[self.regions["id"]] = scale
        return _on_grid(self._grid, by_label[labels], "field_scale_m", np.nan)

    vertex_labels = property(lambda self: self._native.vertex_labels)
    region_count = property(lambda self: self._native.region_count)
    critical_before = property(lambda self: self._native.critical_before)
    critical_after = property(lambda self: self._native.critical_after)
    timings = property(lambda self: self._native.timings)
    dem = property(lambda self: self._native.dem)
    point_frame = property(lambda self: self._native.point_frame)

    @property
    def craters(self):
        columns = self._native.crater_columns
        if columns is None:
            return None
        import geopandas
        import pandas

        table = pandas.DataFrame(columns)
        x, y = ("lon", "lat") if "lon" in columns else ("x", "y")
        crs = self._native.crater_crs
        if crs is None and "lon" not in columns:
            crs = self.dem.crs if self.dem is not None and self.dem.crs else None
        return geopandas.GeoDataFrame(
            table, geometry=geopandas.points_from_xy(table[x], table[y]), crs=crs)

    def to_geodataframe(self):
        """The region polygons with the region table's columns, as a geopandas.GeoDataFrame
        in the DEM's CRS (the polygons of the command line's regions file)."""
        return _geodataframe(lambda p: self._native.write_polygons(p, "GPKG"), self.regions)

    def write(self, directory, overwrite=False, progress=None):
        """Write every output of `terrain segment` (labels.tif, regions.geojson,
        adjacency.*, preview.png, run.json) into `directory`; returns the file names."""
        return self._native.write(self._options, os.fspath(directory), overwrite,
                                  self._input_path, progress)

    def __repr__(self):
        return f"<terrain.SegmentResult: {self.region_count} regions>"


def segment(dem, geotransform=None, crs=None, *, progress=None, **options):
    """Segment a DEM (or a mesh file) into landform regions, as `terrain segment` does.

    Given no scale option (rings, radius, radii, persistence, area_ratio, min_area), a DEM
    takes the landform defaults: radius="auto", min_area="auto" (docs/segment.md); any of
    them gives the paper's single scale for the rest (rings=2, persistence=10,
    area_ratio=0.5).

    dem: a path (DEM or .off/.ply/.obj mesh), a terrain.Dem, or a 2-D numpy array of
        elevations in metres (NaN = NoData) with its GDAL `geotransform` (6 numbers or an
        affine.Affine) and `crs` (WKT, "EPSG:32611", "IAU_2015:30100", or a CRS object);
        or an xarray DataArray with its CRS and transform (rioxarray's .rio; NoData from
        .rio.nodata/_FillValue or NaN, scale_factor/add_offset applied, dask chunks read
        one by one; band=N picks a band), whose labels, field and field_scale_m are then
        DataArrays on its grid.
    options (keywords, the command line's defaults): field="shape-index" (or "sdf",
        "height"), rings=2, radius=0 (metres, or "auto": chosen per vertex among radii, a
        list of metres; docs/field.md), window="disk" (or "ball"), rays=25, cone_angle=120,
        postprocess=True,
        allow_open=False, persistence=10, area_ratio=0.5 (percent) or min_area (an area on
        the body: m^2 as a number, or "5km2", "2000m2", "3ha"; an arc is cancelled when its
        area is below it, whatever the tile's extent), cost="auto" ("graph",
        "standard"), saddle_penalty=20, absorbed="auto" ("divide" for DEMs, "whole", the
        paper's growing, for meshes), format="GeoJSON", craters=True (segment only: the
        craters read from the regions, .craters; docs/craters.md); reading: band=1,
        elevation="auto", nan_nodata=False, pixel_size=None, frame="auto", repair=False,
        max_memory=None (bytes, or "512M", "4G" as --max-memory: a file whose estimated
        peak memory exceeds it, or the memory available, is refused before it is read).
    progress: optional callable progress(fraction, message); return False to cancel.
    Returns a SegmentResult (.labels, .regions, .graph, .to_geodataframe(), .write()).
    Raises terrain.Error on bad input or options, TypeError on an unknown option.
    """
    native_options, read = _split_options(options, _SEGMENT_OPTIONS)
    source, read, grid = _prepare(dem, geotransform, crs, read)
    native = _terrain.segment(source, native_options, progress=progress, **read)
    return SegmentResult(native, native_options, _input_path(source), grid)


class SweepScale:
    """One scale of a sweep: ratio (percent), min_area (m^2, a sweep over areas; else None),
    labels, vertex_labels, regions, graph, region_count. For a DataArray input, labels is a
    DataArray on its grid with attributes area_ratio (and min_area_m2)."""

    def __init__(self, sweep, index, grid=None):
        self._sweep = sweep
        self._index = index
        self._grid = grid
        self.ratio = sweep.ratios[index]
        self.min_area = sweep.min_areas[index] or None
        self.regions = sweep.region_columns(index)
        self.graph = RegionGraph(self.regions, sweep.edge_columns(index))
        self.region_count = sweep.region_count(index)
        self.critical_after = sweep.critical_after(index)

    @property
    def labels(self):
        attrs = {"area_ratio": self.ratio}
        if self.min_area is not None:
            attrs["min_area_m2"] = self.min_area
        return _on_grid(self._grid, self._sweep.labels(self._index), "labels", 0, attrs)

    vertex_labels = property(lambda self: self._sweep.vertex_labels(self._index))

    def to_geodataframe(self):
        """This scale's region polygons as a geopandas.GeoDataFrame."""
        return _geodataframe(lambda p: self._sweep.write_polygons(self._index, p, "GPKG"),
                             self.regions)


class SweepResult:
    """What terrain.sweep returns: .scales (by increasing area ratio), .lineage(i) (how the
    regions of scale i overlap those of scale i + 1: from_region, to_region, area_m2,
    fraction columns), .write(directory)."""

    def __init__(self, native, options, input_path, grid=None):
        self._native = native
        self._options = options
        self._input_path = input_path
        self.scales = [SweepScale(native, i, grid) for i in range(native.scale_count())]
        self.critical_before = native.critical_before

    def lineage(self, index):
        return self._native.lineage(index)

    def write(self, directory, overwrite=False, progress=None):
        """Write every output of `terrain sweep` into `directory`; returns the file names."""
        return self._native.write(self._options, os.fspath(directory), overwrite,
                                  self._input_path, progress)


def sweep(dem, geotransform=None, crs=None, *, area_ratios=None, min_areas=None,
          progress=None, **options):
    """Segment at several area ratios (percent; default 0.1, 0.25, 0.5, 1, 2) or at several
    areas on the body (min_areas: m^2 numbers or texts such as "1km2", as `terrain sweep
    --min-areas`) from one field and Reeb graph, as `terrain sweep` does; the other options
    are segment()'s. Returns a SweepResult."""
    if area_ratios is not None and min_areas is not None:
        raise Error("sweep: give area_ratios or min_areas, not both")
    if area_ratios is None:
        area_ratios = (0.1, 0.25, 0.5, 1, 2)
    areas = [a if isinstance(a, str) else repr(float(a)) for a in (min_areas or [])]
    if min_areas is not None and not areas:
        raise Error("sweep: --min-areas needs at least one value")
    native_options, read = _split_options(options, _OPTIONS_BUT_CRATERS)
    source, read, grid = _prepare(dem, geotransform, crs, read)
    native = _terrain.sweep(source, [float(r) for r in area_ratios], native_options,
                            progress=progress, min_areas=areas, **read)
    return SweepResult(native, native_options, _input_path(source), grid)


def shape_index(dem, geotransform=None, crs=None, *, rings=2, radius=0.0, window="disk",
                progress=None, **read):
    """The shape index x100 (0 cup, 50 saddle or plane, 100 cap) of each DEM pixel, a 2-D
    float32 array (NaN = NoData), fitted over the vertices within `rings` mesh edges or
    `radius` metres (window "disk": on the ground, or "ball": in 3-D); per vertex (1-D)
    for a mesh file; a DataArray on the grid of a DataArray input."""
    options = {"field": "shape-index", "radius": radius, "window": window, **read}
    if not radius:
        options["rings"] = rings
    native_options, read = _split_options(options, _OPTIONS_BUT_CRATERS)
    source, read, grid = _prepare(dem, geotransform, crs, read)
    values = _terrain.field(source, native_options, progress=progress, **read)
    return _on_grid(grid, values, "shape_index", np.nan)


class ReebGraph:
    """The Reeb graph of a field: its critical nodes and the arcs between them.

    nodes: node, value, kind ("min", "max", "saddle"), vertex (a mesh vertex of the
        node), vertex_count, col, row (its DEM pixel; -1 for mesh files).
    arcs: lower, upper (indices into the node columns), regular_nodes.
    critical_before: critical nodes before simplification.
    """

    def __init__(self, nodes, arcs, critical_before):
        self.nodes = nodes
        self.arcs = arcs
        self.critical_before = critical_before

    def to_networkx(self):
        """A networkx.MultiDiGraph, arcs from their lower to their upper node (parallel arcs
        are the graph's loops)."""
        import networkx as nx

        g = nx.MultiDiGraph()
        for i in range(len(self.nodes["node"])):
            g.add_node(i, **{k: _scalar(v[i]) for k, v in self.nodes.items()})
        for i in range(len(self.arcs["lower"])):
            g.add_edge(int(self.arcs["lower"][i]), int(self.arcs["upper"][i]),
                       regular_nodes=int(self.arcs["regular_nodes"][i]))
        return g


def reeb_graph(dem, geotransform=None, crs=None, *, persistence=0.0, area_ratio=None,
               min_area=None, progress=None, **options):
    """The Reeb graph of the field (shape index by default) on the DEM's mesh, simplified
    when persistence, area_ratio (percent) or min_area (as in segment()) is above 0, as
    `terrain reeb` builds it. Field and reading options as in segment(). Returns a
    ReebGraph."""
    if area_ratio is not None and min_area is not None:
        raise Error("segment: give area_ratio or min_area, not both")
    options = dict(options, persistence=persistence)
    if min_area is not None:
        options["min_area"] = min_area
    else:
        options["area_ratio"] = 0.0 if area_ratio is None else area_ratio
    native_options, read = _split_options(options, _OPTIONS_BUT_CRATERS)
    source, read, _ = _prepare(dem, geotransform, crs, read)
    nodes, arcs, before = _terrain.reeb_graph(source, native_options, progress=progress, **read)
    return ReebGraph(nodes, arcs, before)


def _register_xarray_accessor():
    from . import _xarray

    _xarray.register_accessor()


class _AccessorOnXarrayImport(importlib.abc.MetaPathFinder):
    """Registers DataArray.terrain right after xarray is first imported: `import terrain`
    itself does not import xarray (it takes seconds), yet da.terrain works whichever of
    the two is imported first. Finds nothing itself; it leaves sys.meta_path at once."""

    def find_spec(self, name, path=None, target=None):
        if name != "xarray":
            return None
        if self in sys.meta_path:
            sys.meta_path.remove(self)
        for finder in sys.meta_path:
            spec = finder.find_spec(name, path, target) if hasattr(finder, "find_spec") else None
            if spec is not None:
                break
        else:
            return None
        loader = spec.loader
        if loader is None or isinstance(loader, type) or not hasattr(loader, "exec_module"):
            return spec
        run = loader.exec_module

        def exec_module(module):
            run(module)
            _register_xarray_accessor()

        loader.exec_module = exec_module  # this spec's own loader object
        return spec


if sys.modules.get("xarray") is not None:
    _register_xarray_accessor()
else:
    sys.meta_path.insert(0, _AccessorOnXarrayImport())
