"""xarray DataArrays (rioxarray): in as DEMs, out as labels on the input's grid; the
.terrain accessor; NoData; dask chunks read one by one; one clear error for what is
missing."""

import subprocess
import sys
import tracemalloc

import dask.array
import numpy as np
import pytest
import rioxarray
import xarray as xr
from osgeo import gdal, osr

import terrain
from conftest import SAMPLE_FILES

gdal.UseExceptions()

# The Moon crop and the global Moon sample (Int16, scale 0.5, offset 1737400, NoData -32768).
ROUND_TRIP = ["moon4c", "moon1g"]


def same_crs(wkt_a, wkt_b):
    a, b = osr.SpatialReference(), osr.SpatialReference()
    a.ImportFromWkt(wkt_a)
    b.ImportFromWkt(wkt_b)
    return bool(a.IsSame(b))


@pytest.mark.parametrize("name", ROUND_TRIP)
def test_labels_round_trip_through_rioxarray(name, tmp_path):
    path = str(SAMPLE_FILES[name])
    expected = terrain.segment(path)
    da = rioxarray.open_rasterio(path)
    result = terrain.segment(da)
    labels = result.labels
    assert isinstance(labels, xr.DataArray)
    assert labels.dims == ("y", "x") and labels.dtype == np.uint32
    assert np.array_equal(labels["x"].values, da["x"].values)
    assert np.array_equal(labels["y"].values, da["y"].values)
    assert labels.rio.crs == da.rio.crs
    assert labels.rio.transform() == da.rio.transform()
    assert labels.rio.nodata == 0
    out = tmp_path / "labels.tif"
    labels.rio.to_raster(out)
    ds = gdal.Open(str(out))
    band = ds.GetRasterBand(1)
    back = band.ReadAsArray()
    assert back.dtype == np.uint32
    assert back.tobytes() == expected.labels.tobytes()
    assert band.GetNoDataValue() == 0
    src = gdal.Open(path)
    assert same_crs(ds.GetProjection(), src.GetProjection())
    # rioxarray writes the pixel size it reads back from the coordinates: equal to the last
    # bits.
    assert ds.GetGeoTransform() == pytest.approx(src.GetGeoTransform(), rel=1e-13, abs=1e-6)
    # The region table and the field are those of the path.
    for key in ("id", "area_m2", "field_mean", "landform", "point_x"):
        assert np.array_equal(result.regions[key], expected.regions[key])
    assert result.field.values.tobytes() == expected.field.tobytes()
    assert result.field.rio.crs == da.rio.crs
    # The scale chosen for each region, on its pixels.
    scale = result.field_scale_m
    assert scale.dims == ("y", "x") and scale.rio.crs == da.rio.crs
    assert np.array_equal(scale.values, expected.field_scale_m, equal_nan=True)
    by_id = dict(zip(expected.regions["id"], expected.regions["field_scale_m"]))
    row, col = np.argwhere(expected.labels > 0)[len(by_id) // 2]
    assert scale.values[row, col] == by_id[expected.labels[row, col]] > 0


def test_the_accessor_and_the_numpy_route_give_the_same_bytes():
    path = str(SAMPLE_FILES["moon4c"])
    da = rioxarray.open_rasterio(path)
    by_accessor = da.terrain.segment(persistence=5, area_ratio=1)
    ds = gdal.Open(path)
    band = ds.GetRasterBand(1)
    values = band.ReadAsArray().astype(np.float64)
    values[values == band.GetNoDataValue()] = np.nan
    values = values * band.GetScale() + band.GetOffset()
    by_array = terrain.segment(values, ds.GetGeoTransform(), ds.GetProjection(),
                               persistence=5, area_ratio=1)
    assert by_accessor.labels.values.tobytes() == by_array.labels.tobytes()
    assert by_accessor.region_count == by_array.region_count
    assert by_accessor.region_count != terrain.segment(path).region_count  # options reached


def test_a_dask_backed_dataarray_gives_the_same_labels():
    path = str(SAMPLE_FILES["moon4c"])
    eager = rioxarray.open_rasterio(path)
    lazy = rioxarray.open_rasterio(path, chunks=(1, 40, 50))  # uneven chunks at the edges
    assert lazy.chunks is not None and len(lazy.chunks[1]) == 3 and len(lazy.chunks[2]) == 3
    expected = terrain.segment(path)
    got = lazy.terrain.segment()
    assert got.labels.values.tobytes() == expected.labels.tobytes()
    assert np.array_equal(got.labels["x"].values, eager["x"].values)
    si = terrain.shape_index(lazy, rings=3)
    assert si.values.tobytes() == terrain.shape_index(path, rings=3).tobytes()
    assert si.name == "shape_index" and si.rio.crs == eager.rio.crs


class Recording:
    """An int16 array that records each block asked of it."""

    def __init__(self, values):
        self.values = values
        self.shape, self.dtype, self.ndim = values.shape, values.dtype, values.ndim
        self.asked = []

    def __getitem__(self, key):
        block = self.values[key]
        self.asked.append(block.size)
        return block


def test_a_dask_array_is_read_chunk_by_chunk_into_one_array():
    from terrain import _xarray

    src = rioxarray.open_rasterio(str(SAMPLE_FILES["moon1g"]))
    raw = src.values[0]
    big = np.tile(raw, (4, 4))  # 720 x 1440 pixels, 8.3 MB as float64
    recording = Recording(big)
    chunks = (90, 180)
    lazy = dask.array.from_array(recording, chunks=chunks, asarray=False)
    da = xr.DataArray(lazy, dims=("y", "x"), attrs=dict(src.attrs))
    da = da.rio.write_crs(src.rio.crs).rio.write_transform(src.rio.transform())
    recording.asked.clear()
    tracemalloc.start()
    try:
        with dask.config.set(num_workers=2):  # chunks in flight: as on any machine
            values, _, _, _ = _xarray.dem_source(da, 1)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    expected = np.where(big == -32768, np.nan, big * 0.5 + 1737400.0)
    assert values.tobytes() == expected.tobytes()
    assert len(recording.asked) == 64 and max(recording.asked) == chunks[0] * chunks[1]
    # The float64 array, a few chunks and dask's graph: not the whole raw array as well
    # (2 bytes a pixel, 2 MB), as a read of the whole (.values) would hold.
    assert values.nbytes < peak < values.nbytes + big.nbytes * 3 // 4


def test_nodata_from_fill_value_nodata_or_nan():
    path = str(SAMPLE_FILES["moon4c"])
    raw = rioxarray.open_rasterio(path)
    raw.values[0, 30:50, 60:90] = raw.rio.nodata  # a hole of -32768 (the _FillValue)
    with_holes = terrain.segment(raw)
    labels = with_holes.labels.values
    assert (labels[30:50, 60:90] == 0).all() and (labels == 0).sum() == 20 * 30
    # The same hole as NaN (rioxarray's masked and scaled float32), and as a NoData value
    # of float heights written with .rio.write_nodata.
    masked = rioxarray.open_rasterio(path, mask_and_scale=True)
    masked.values[0, 30:50, 60:90] = np.nan
    numpy_values = np.where(raw.values[0] == -32768, np.nan, raw.values[0] * 0.5 + 1737400.0)
    heights = raw.copy(data=np.where(np.isnan(numpy_values), -1.0, numpy_values)[None])
    heights.attrs = {}  # metres: no scale_factor, add_offset, _FillValue
    heights = heights.rio.write_nodata(-1.0)
    for other in (masked, heights):
        assert terrain.segment(other).labels.values.tobytes() == labels.tobytes()
    # And the numpy route with NaN.
    by_array = terrain.segment(numpy_values, raw.rio.transform(), raw.rio.crs)
    assert by_array.labels.tobytes() == labels.tobytes()


def test_sweep_scales_are_dataarrays_with_their_scale():
    path = str(SAMPLE_FILES["moon4c"])
    da = rioxarray.open_rasterio(path)
    ratios = [0.25, 1]
    expected = terrain.sweep(path, area_ratios=ratios)
    got = da.terrain.sweep(area_ratios=ratios)
    for s, e in zip(got.scales, expected.scales):
        assert s.labels.values.tobytes() == e.labels.tobytes()
        assert s.labels.attrs["area_ratio"] == e.ratio
        assert s.labels.rio.crs == da.rio.crs
    by_area = da.terrain.sweep(min_areas=["2000km2"])
    assert by_area.scales[0].labels.attrs["min_area_m2"] == 2e9


def test_bands_and_the_order_of_dimensions():
    path = str(SAMPLE_FILES["moon4c"])
    one = rioxarray.open_rasterio(path)
    mirrored = one.copy(data=one.values[:, ::-1, :])  # another surface on the same grid
    two = xr.concat([one, mirrored], dim="band")
    two["band"] = [1, 2]
    two = two.rio.write_crs(one.rio.crs)
    two.attrs = dict(one.attrs)
    first, second = terrain.segment(two), terrain.segment(two, band=2)
    assert first.labels.values.tobytes() == terrain.segment(path).labels.tobytes()
    assert second.labels.values.tobytes() == terrain.segment(mirrored).labels.values.tobytes()
    assert second.labels.values.tobytes() != first.labels.values.tobytes()
    # (x, y) order: the same regions, put back as (y, x).
    flipped = terrain.segment(one.transpose("band", "x", "y")).labels
    assert flipped.dims == ("y", "x")
    assert flipped.values.tobytes() == first.labels.values.tobytes()


def test_what_is_missing_is_one_clear_error():
    path = str(SAMPLE_FILES["moon4c"])
    full = rioxarray.open_rasterio(path)
    values = full.values[0] * 0.5 + 1737400.0
    bare = xr.DataArray(values, dims=("y", "x"))
    with pytest.raises(terrain.Error, match=r"^read: the DataArray has no CRS .* and no "
                                            r"transform .*; terrain needs both"):
        terrain.segment(bare)
    with_crs = bare.rio.write_crs(full.rio.crs)
    with pytest.raises(terrain.Error, match=r"^read: the DataArray has no transform \("):
        with_crs.terrain.segment()
    with_transform = bare.rio.write_transform(full.rio.transform())
    with pytest.raises(terrain.Error, match=r"^read: the DataArray has no CRS \("):
        terrain.shape_index(with_transform)
    # Both, without x/y coordinates: the grid mapping's GeoTransform places the grid.
    both = with_crs.rio.write_transform(full.rio.transform())
    assert "x" not in both.coords
    labels = terrain.segment(both).labels
    assert labels.values.tobytes() == terrain.segment(path).labels.tobytes()
    assert labels.rio.transform() == full.rio.transform()
    with pytest.raises(terrain.Error, match="no spatial dimensions"):
        terrain.segment(xr.DataArray(values, dims=("row", "col")))
    with pytest.raises(terrain.Error, match="not a Dataset"):
        terrain.segment(xr.Dataset({"h": bare}))
    with pytest.raises(terrain.Error, match="do not pass geotransform or crs"):
        terrain.segment(full, crs="IAU_2015:30100")
    with pytest.raises(terrain.Error, match=r"band 2 asked of a DataArray of 1 band"):
        terrain.sweep(full, band=2)
    with pytest.raises(terrain.Error, match="must be 2-D"):
        terrain.segment(full.expand_dims(time=[0]))


def run_python(code):
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_the_accessor_is_registered_lazily():
    # import terrain does not import xarray; da.terrain exists whichever comes first.
    out = run_python("import sys, terrain; print('xarray' in sys.modules); import xarray; "
                     "print(xarray.DataArray.terrain.__name__)")
    assert out.split() == ["False", "TerrainAccessor"]
    out = run_python("import xarray, terrain; print(xarray.DataArray.terrain.__name__)")
    assert out.split() == ["TerrainAccessor"]
    # Without xarray the module imports and segments arrays.
    out = run_python(
        "import sys; sys.modules['xarray'] = None\n"
        "import numpy as np, terrain\n"
        "z = np.add.outer(np.sin(np.arange(20) / 3), np.cos(np.arange(30) / 4)) * 50\n"
        "print(terrain.segment(z, (0, 30, 0, 0, 0, -30), 'EPSG:32611').region_count > 1)")
    assert out.split() == ["True"]
