#include "terrain/io/read_dem.hpp"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal_priv.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>

#include "gdal_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/geo/body.hpp"
#include "terrain/geo/georeference.hpp"
#include "validate_dem.hpp"

namespace terrain::io {

ElevationKind detect_elevation_kind(const Body& body, double min_value, double max_value) {
    // A radius DEM holds values close to the body's radius; heights above a reference never
    // reach half of it (Vesta's relief, the largest relative to its size, is about +-10%).
    if (body.has_crs && body.semi_major_axis > 0 && min_value > 0.5 * body.semi_major_axis &&
        max_value < 1.5 * body.semi_major_axis)
        return ElevationKind::radius;
    return ElevationKind::height;
}

namespace {

// The raster at `path` opened, with the band asked for.
std::unique_ptr<GDALDataset> open_dem(const std::string& path, const ReadDemOptions& options,
                                      const GdalErrorCapture& errors) {
    if (!std::filesystem::exists(path) && path.rfind("/vsi", 0) != 0)
        throw Error("read", "'" + path + "' does not exist; check the path");
    std::unique_ptr<GDALDataset> dataset(
        GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY));
    if (!dataset)
        throw Error("read", "'" + path + "' is not a raster GDAL can open" + errors.suffix() +
                                "; give a DEM such as a GeoTIFF or a PDS label");
    const int band_count = dataset->GetRasterCount();
    if (band_count == 0) throw Error("read", "'" + path + "' has no raster band");
    if (options.band < 1 || options.band > band_count)
        throw Error("read", "band " + std::to_string(options.band) + " does not exist in '" + path +
                                "', which has " + std::to_string(band_count) +
                                " band(s); choose --band 1.." + std::to_string(band_count));
    return dataset;
}

// The grid of the dataset: its size, geotransform, CRS, body and georeference, checked
// before anything reads its values.
Dem dem_grid(const std::string& path, const ReadDemOptions& options, GDALDataset& dataset) {
    Dem dem;
    dem.source = path;
    dem.band = options.band;
    dem.width = dataset.GetRasterXSize();
    dem.height = dataset.GetRasterYSize();
    if (dem.width < 2 || dem.height < 2)
        throw Error("read", "'" + path + "' is " + std::to_string(dem.width) + "x" +
                                std::to_string(dem.height) +
                                " pixels; a surface needs at least 2x2 pixels");

    dem.has_transform = dataset.GetGeoTransform(dem.transform.data()) == CE_None;
    if (!dem.has_transform) {
        const double size = options.pixel_size.value_or(1.0);
        dem.transform = {0, size, 0, 0, 0, -size};
    } else if (options.pixel_size) {
        throw Error("read", "'" + path +
                                "' is georeferenced; --pixel-size is only for rasters without a "
                                "geotransform");
    }
    if (const OGRSpatialReference* srs = dataset.GetSpatialRef()) {
        char* wkt = nullptr;
        const char* wkt_options[] = {"FORMAT=WKT2_2019", nullptr};
        if (srs->exportToWkt(&wkt, wkt_options) == OGRERR_NONE && wkt) dem.crs_wkt = wkt;
        CPLFree(wkt);
    }
    // The grid is checked before anything reads it (a hostile geotransform or pixel size
    // would make the georeference loop or the arrays absurd).
    dem.body = geo::body_from_crs(dem.crs_wkt);
    validate_dem_grid(path, dem, dataset.GetSpatialRef());
    geo::georeference(dem);                     // the body, and where the pixels lie on it
    validate_dem_on_body(path, dem, &dataset);  // ... which must be on it

    return dem;
}

// What reading the values found: the valid pixels and their range, the values neither valid
// nor NoData (NaN or infinite) and the first of them.
struct ValuesRead {
    std::size_t valid = 0, not_finite = 0;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    int first_bad_col = -1, first_bad_row = -1;
};

// The band's values, row by row, scaled by a x + b, into dem.values (or, with `summary`,
// only counted).
ValuesRead read_values(const std::string& path, GDALDataset& dataset, GDALRasterBand& band_ref,
                       Dem& dem, double a, double b, bool all_valid, bool summary,
                       const GdalErrorCapture& errors, const ProgressFn& progress) {
    GDALRasterBand* band = &band_ref;
    GDALRasterBand* mask = band->GetMaskBand();
    const std::size_t width = static_cast<std::size_t>(dem.width);
    ValuesRead read;
    std::size_t& valid = read.valid;
    std::size_t& not_finite = read.not_finite;
    double& lo = read.lo;
    double& hi = read.hi;
    int& first_bad_col = read.first_bad_col;
    int& first_bad_row = read.first_bad_row;
    std::vector<double> row_values(summary ? width : 0);
    std::vector<unsigned char> mask_row(all_valid ? 0 : width);
    // A summary reads one row of blocks at a time, drops GDAL's cached blocks after each, and
    // skips the blocks a sparse file does not hold (all NoData, or all zero without NoData).
    int block_width = 0, block_height = 0;
    band->GetBlockSize(&block_width, &block_height);
    block_height = std::max(1, block_height);
    const bool known_fill = all_valid || band->GetMaskFlags() == GMF_NODATA;
    for (int row = 0; row < dem.height; ++row) {
        if (summary && row % block_height == 0) {
            if (row > 0) dataset.FlushCache(false);
            const int rows = std::min(block_height, dem.height - row);
            if (known_fill && band->GetDataCoverageStatus(0, row, dem.width, rows, 0, nullptr) ==
                                  GDAL_DATA_COVERAGE_STATUS_EMPTY) {
                if (all_valid) {
                    lo = std::min(lo, b);
                    hi = std::max(hi, b);
                    valid += width * static_cast<std::size_t>(rows);
                }
                row += rows - 1;
                continue;
            }
        }
        if (!summary) {
            if (row == 1) dem.values.reserve(width * static_cast<std::size_t>(dem.height));
            dem.values.resize(static_cast<std::size_t>(row + 1) * width,
                              std::numeric_limits<double>::quiet_NaN());
        }
        double* out =
            summary ? row_values.data() : dem.values.data() + static_cast<std::size_t>(row) * width;
        if (band->RasterIO(GF_Read, 0, row, dem.width, 1, out, dem.width, 1, GDT_Float64, 0, 0) !=
            CE_None)
            throw Error("read", "cannot read row " + std::to_string(row) + " of '" + path + "'" +
                                    errors.suffix());
        if (!all_valid && mask->RasterIO(GF_Read, 0, row, dem.width, 1, mask_row.data(), dem.width,
                                         1, GDT_Byte, 0, 0) != CE_None)
            throw Error("read", "cannot read the NoData mask of '" + path + "'" + errors.suffix());
        for (std::size_t col = 0; col < width; ++col) {
            double& v = out[col];
            if (!all_valid && mask_row[col] == 0) {
                v = std::numeric_limits<double>::quiet_NaN();
                continue;
            }
            if (!std::isfinite(v)) {
                if (not_finite++ == 0) {
                    first_bad_col = static_cast<int>(col);
                    first_bad_row = row;
                }
                v = std::numeric_limits<double>::quiet_NaN();
                continue;
            }
            v = v * a + b;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
            ++valid;
        }
        if ((row & 63) == 0) report_progress(progress, double(row) / dem.height, "read");
    }
    return read;
}

// `summary`: statistics only, the values are not kept (Dem::values stays empty).
Dem read_dem(const std::string& path, const ReadDemOptions& options, const ProgressFn& progress,
             DemValueSummary* summary) {
    ensure_gdal_registered();
    const GdalErrorCapture errors;
    const std::unique_ptr<GDALDataset> dataset = open_dem(path, options, errors);
    Dem dem = dem_grid(path, options, *dataset);
    GDALRasterBand* band = dataset->GetRasterBand(options.band);
    int has_scale = 0, has_offset = 0;
    const double scale = band->GetScale(&has_scale);
    const double offset = band->GetOffset(&has_offset);
    const double a = has_scale ? scale : 1.0;
    const double b = has_offset ? offset : 0.0;
    validate_scale(path, a, b);
    const bool all_valid = band->GetMaskFlags() == GMF_ALL_VALID;
    check_dem_size(path, dem, *band, summary ? nullptr : &options.memory, all_valid);
    // Each row of the grid's values is added as it is read, and the whole grid is reserved
    // (address space only) once the first row has been read: the memory used follows what
    // the file gives, not what its header claims. An 826-byte GeoTIFF declaring 18464 x 65504
    // pixels used to fill 9.7 GB with NaN before its first row failed to read.
    const ValuesRead read = read_values(path, *dataset, *band, dem, a, b, all_valid,
                                        summary != nullptr, errors, progress);
    const std::size_t valid = read.valid, not_finite = read.not_finite;
    const double lo = read.lo, hi = read.hi;
    const int first_bad_col = read.first_bad_col, first_bad_row = read.first_bad_row;
    if (not_finite > 0 && !options.nan_as_nodata)
        throw Error("read", "'" + path + "' has " + std::to_string(not_finite) +
                                " NaN or infinite value(s) not declared NoData (first at col " +
                                std::to_string(first_bad_col) + ", row " +
                                std::to_string(first_bad_row) +
                                "); declare NoData (gdal_edit.py -a_nodata nan) or pass "
                                "--nan-nodata to treat them as holes");
    if (valid == 0)
        throw Error("read",
                    "'" + path + "' band " + std::to_string(options.band) +
                        " has no valid pixel (all NoData); check the band and NoData value");
    if (valid < 3)
        throw Error("read", "'" + path + "' has only " + std::to_string(valid) +
                                " valid pixel(s); a surface needs at least three");
    validate_value_range(path, lo, hi);
    if (summary) *summary = {lo, hi, valid};
    // Before the mesh and all that follows: the plan with the valid pixels counted.
    if (!summary && !all_valid) check_dem_valid_pixels(path, dem, valid, &options.memory);

    if (options.elevation) {
        dem.elevation = *options.elevation;
        dem.elevation_detected = false;
        if (dem.elevation == ElevationKind::radius && !dem.body.has_crs)
            throw Error("read", "'" + path +
                                    "' has no CRS, so its values cannot be radii of a body; use "
                                    "--elevation height");
    } else {
        dem.elevation = detect_elevation_kind(dem.body, lo, hi);
    }
    validate_dem_heights(path, dem, dataset.get(), lo);
    report_progress(progress, 1.0, "read");
    return dem;
}

}  // namespace

Dem read_dem(const std::string& path, const ReadDemOptions& options, const ProgressFn& progress) {
    return read_dem(path, options, progress, nullptr);
}

void check_dem_on_body(const Dem& dem) {
    double lo = std::numeric_limits<double>::infinity();
    for (double v : dem.values)
        if (std::isfinite(v)) lo = std::min(lo, v);
    const std::string name = dem.source.empty() ? "<grid>" : dem.source;
    validate_dem_on_body(name, dem, nullptr);
    if (std::isfinite(lo)) validate_dem_heights(name, dem, nullptr, lo);
}

Dem read_dem_summary(const std::string& path, DemValueSummary& summary,
                     const ReadDemOptions& options, const ProgressFn& progress) {
    return read_dem(path, options, progress, &summary);
}

}  // namespace terrain::io
