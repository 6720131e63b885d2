"""xarray DataArrays in and out of terrain (docs/python.md, "xarray and rioxarray").

A DataArray with a CRS and a transform (rioxarray's `.rio`) goes in where a DEM array goes;
the per-pixel results come back as DataArrays on its grid: its x/y coordinates, its CRS,
its transform, ready for `.rio.to_raster`. Imported only when a DataArray is given or when
xarray itself is imported (the `.terrain` accessor), so that `import terrain` does not pay
for xarray.
"""

import numpy as np
import xarray

from ._terrain import Error

# Pixels converted at a time from a DataArray that is not dask-backed (a strip of rows).
_STRIP_PIXELS = 1 << 22


def _spatial_dims(da):
    try:
        return da.rio.y_dim, da.rio.x_dim
    except Exception:  # rioxarray's MissingSpatialDimensionError and kin
        raise Error(f"read: the DataArray has no spatial dimensions rioxarray knows (its dims "
                    f"are {tuple(da.dims)}); name them y and x (or lat and lon), or call "
                    f"da.rio.set_spatial_dims(x_dim=..., y_dim=...)") from None


def _has_geotransform(da):
    mapping = da.coords.get(da.rio.grid_mapping)
    return mapping is not None and "GeoTransform" in mapping.attrs


def _one_band(da, band, y_dim, x_dim):
    """The 2-D (y, x) DataArray of band `band` (1-based, the `band` option)."""
    others = [d for d in da.dims if d not in (y_dim, x_dim)]
    if len(others) > 1 or da.ndim < 2:
        raise Error(f"read: the DataArray must be 2-D (y, x) or 3-D (band, y, x); its dims are "
                    f"{tuple(da.dims)}")
    if others:
        count = da.sizes[others[0]]
        if not 1 <= band <= count:
            raise Error(f"read: band {band} asked of a DataArray of {count} band(s) along "
                        f"'{others[0]}'")
        da = da.isel({others[0]: band - 1})
    if da.dims != (y_dim, x_dim):
        da = da.transpose(y_dim, x_dim)
    return da


class Grid:
    """The grid of a DataArray: what the results are put back on."""

    def __init__(self, da, y_dim, x_dim):
        self.dims = (y_dim, x_dim)
        self.coords = {d: da[d].variable for d in self.dims if d in da.coords}
        self.crs = da.rio.crs
        self.transform = da.rio.transform()

    def wrap(self, values, name, nodata, attrs=None):
        """`values` (2-D, the DEM's shape) as a DataArray on this grid."""
        out = xarray.DataArray(values, dims=self.dims, coords=self.coords, name=name,
                               attrs=dict(attrs or {}))
        out = out.rio.write_crs(self.crs)
        out = out.rio.write_transform(self.transform)
        return out.rio.write_nodata(nodata, encoded=False)


def _decoding(da):
    """NoData, scale and offset of the raw values, as GDAL reads a file's band: a value equal
    to NoData (.rio.nodata, _FillValue) or NaN is a hole; the rest become value * scale +
    offset (attributes scale_factor and add_offset: rioxarray's undecoded values)."""
    nodata = da.rio.nodata
    if nodata is not None:
        nodata = float(nodata)
        if np.isnan(nodata):
            nodata = None  # NaN is always a hole
    scale = float(da.attrs.get("scale_factor", 1.0))
    offset = float(da.attrs.get("add_offset", 0.0))
    return nodata, scale, offset


def _decode(block, nodata, scale, offset):
    out = np.asarray(block).astype(np.float64)
    if nodata is not None:
        out[np.asarray(block) == nodata] = np.nan
    if scale != 1.0:
        out *= scale
    if offset != 0.0:
        out += offset
    return out


def _metres(da):
    """The DataArray's elevations in metres as one float64 array (NaN = NoData), filled in
    place: chunk by chunk from a dask array, strip by strip from anything else, so that no
    more than the array itself and a few blocks is ever held."""
    nodata, scale, offset = _decoding(da)
    out = np.empty(da.shape, dtype=np.float64)
    if da.chunks is not None:
        import dask.array

        decoded = da.data.map_blocks(_decode, nodata, scale, offset, dtype=np.float64)
        dask.array.store(decoded, out, lock=False)
        return out
    rows = max(1, _STRIP_PIXELS // max(1, da.shape[1]))
    y_dim = da.dims[0]
    for row in range(0, da.shape[0], rows):
        strip = da.isel({y_dim: slice(row, row + rows)})
        out[row:row + rows] = _decode(strip.values, nodata, scale, offset)
    return out


def dem_source(da, band):
    """(values, geotransform, CRS WKT, Grid) of a DataArray with a CRS and a transform."""
    try:  # registers .rio: the CRS, the transform and NoData of a DataArray
        import rioxarray  # noqa: F401
    except ImportError:
        raise Error("read: a DataArray is read through rioxarray's .rio (CRS, transform, "
                    "NoData): apt install python3-rioxarray") from None
    y_dim, x_dim = _spatial_dims(da)
    da = _one_band(da, band, y_dim, x_dim)
    missing = []
    if da.rio.crs is None:
        missing.append("no CRS (da.rio.write_crs(...))")
    if not (y_dim in da.coords and x_dim in da.coords) and not _has_geotransform(da):
        missing.append(f"no transform (neither {y_dim}/{x_dim} coordinates nor "
                       f"da.rio.write_transform(...))")
    if missing:
        raise Error("read: the DataArray has " + " and ".join(missing) +
                    "; terrain needs both to place the DEM on its body")
    grid = Grid(da, y_dim, x_dim)
    wkt = grid.crs.to_wkt(version="WKT2_2019")
    return _metres(da), grid.transform.to_gdal(), wkt, grid


def is_dataset(obj):
    return isinstance(obj, xarray.Dataset)


class TerrainAccessor:
    """`da.terrain`: terrain's calls on a DataArray with a CRS and a transform.

    da.terrain.segment(**options) is terrain.segment(da, **options); likewise sweep,
    shape_index and reeb_graph.
    """

    def __init__(self, da):
        self._da = da

    def segment(self, **options):
        """terrain.segment(da, **options): labels, field, field_scale_m as DataArrays."""
        import terrain

        return terrain.segment(self._da, **options)

    def sweep(self, **options):
        """terrain.sweep(da, **options): each scale's labels as a DataArray."""
        import terrain

        return terrain.sweep(self._da, **options)

    def shape_index(self, **options):
        """terrain.shape_index(da, **options): a DataArray on da's grid."""
        import terrain

        return terrain.shape_index(self._da, **options)

    def reeb_graph(self, **options):
        """terrain.reeb_graph(da, **options)."""
        import terrain

        return terrain.reeb_graph(self._da, **options)


_registered = False


def register_accessor():
    """Registers `DataArray.terrain` (once)."""
    global _registered
    if not _registered:
        _registered = True
        xarray.register_dataarray_accessor("terrain")(TerrainAccessor)
