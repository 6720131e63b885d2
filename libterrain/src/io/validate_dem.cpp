#include "validate_dem.hpp"
#include "../core/significant.hpp"

#include <cpl_vsi.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "gdal_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/memory_budget.hpp"

namespace terrain::io {
namespace {

std::string number(double v) {
    return terrain::detail::significant(v, 6);
}

}  // namespace

void validate_dem_grid(const std::string& path, const Dem& dem, const OGRSpatialReference* srs) {
    const auto& t = dem.transform;
    const std::string name = "'" + path + "'";
    for (double v : t)
        if (!std::isfinite(v))
            throw Error("read", name + " has a geotransform with a NaN or infinite term");
    const double step_x = std::hypot(t[1], t[4]), step_y = std::hypot(t[2], t[5]);
    const double determinant = t[1] * t[5] - t[2] * t[4];
    if (step_x == 0 || step_y == 0 || determinant == 0 || !std::isfinite(determinant))
        throw Error("read", name + " has a degenerate geotransform (pixel size " + number(step_x) +
                                " x " + number(step_y) +
                                "); a surface needs pixels of non-zero area");
    const double w = dem.width, h = dem.height;
    if (srs && srs->IsGeographic()) {
        if (step_x < kMinPixelDegrees || step_y < kMinPixelDegrees || step_x > 360 || step_y > 180)
            throw Error("read", name + " has a pixel of " + number(step_x) + " x " +
                                    number(step_y) +
                                    " degrees; a geographic grid needs pixels between " +
                                    number(kMinPixelDegrees) + " and 360 x 180 degrees");
        double lat_lo = 1e300, lat_hi = -1e300, lon_lo = 1e300, lon_hi = -1e300;
        for (const auto& [c, r] : {std::pair{0.0, 0.0}, {w, 0.0}, {0.0, h}, {w, h}}) {
            const auto [lon, lat] = dem.map_xy(c, r);
            lat_lo = std::min(lat_lo, lat);
            lat_hi = std::max(lat_hi, lat);
            lon_lo = std::min(lon_lo, lon);
            lon_hi = std::max(lon_hi, lon);
        }
        // One pixel of slack: grids of pixel centres reach half a pixel past the poles.
        if (lat_lo < -90 - step_y || lat_hi > 90 + step_y)
            throw Error("read", name + " spans latitudes " + number(lat_hi) + " to " +
                                    number(lat_lo) +
                                    " degrees; a geographic grid must stay inside +-90");
        if (lon_hi - lon_lo > 360 + step_x)
            throw Error("read", name + " spans " + number(lon_hi - lon_lo) +
                                    " degrees of longitude; a geographic grid covers at most 360");
        return;
    }
    double unit = 1;  // metres per CRS unit
    if (srs && srs->IsProjected()) unit = srs->GetLinearUnits();
    if (!(unit > 0) || !std::isfinite(unit)) unit = 1;
    const double px = step_x * unit, py = step_y * unit;
    // A pixel larger than half the body's circumference cannot sample its surface.
    const double a = dem.body.semi_major_axis;
    const double largest = a > 0 ? std::numbers::pi * a : kMaxPixelMetres;
    if (std::min(px, py) < kMinPixelMetres || std::max(px, py) > largest)
        throw Error("read", name + " has a pixel of " + number(px) + " x " + number(py) +
                                " m; pixels must be between " + number(kMinPixelMetres) + " and " +
                                number(largest) + " m" +
                                (a > 0 ? " (half the circumference of " + dem.body.name + ")"
                                       : std::string()));
}

namespace {

std::string grid_name(const std::string& path, const Dem& dem) {
    return "the " + std::to_string(dem.width) + "x" + std::to_string(dem.height) + " grid of '" +
           path + "'";
}

}  // namespace

void check_dem_valid_pixels(const std::string& path, const Dem& dem, std::size_t valid,
                            const MemoryPlan* plan) {
    if (!plan || !plan->checked) return;
    const double pixels = double(dem.width) * double(dem.height);
    // (The values just read are resident already: the memory available no longer has them.)
    check_memory(grid_name(path, dem) + " with " + std::to_string(valid) + " valid pixels",
                 plan->dem_bytes(pixels, double(valid)), plan->limit,
                 double(dem.values.capacity() * sizeof(double)));
}

void check_dem_size(const std::string& path, const Dem& dem, GDALRasterBand& band,
                    const MemoryPlan* plan, bool all_valid) {
    const double pixels = double(dem.width) * double(dem.height);
    if (plan && plan->checked)
        check_memory(grid_name(path, dem), plan->dem_bytes(pixels, all_valid ? pixels : 0.0),
                     plan->limit);
    // ASCII grids (GDAL's AAIGrid, GRASSASCIIGrid and ISG drivers) find a line by reading
    // every line before it, again for each one that failed: asking for the last row of a
    // grid whose text ends early takes time exponential in the missing lines. Their size is
    // bounded by the text instead (a value takes at least two characters), and the rows,
    // read from the top, stop at the first one missing.
    const auto* driver = band.GetDataset() ? band.GetDataset()->GetDriver() : nullptr;
    const std::string driver_name = driver ? driver->GetDescription() : "";
    if (driver_name == "AAIGrid" || driver_name == "GRASSASCIIGrid" || driver_name == "ISG") {
        VSIStatBufL stat;
        if (VSIStatL(path.c_str(), &stat) == 0 && 2 * pixels - 1 > double(stat.st_size))
            throw Error("read", "'" + path + "' declares " + std::to_string(dem.width) + "x" +
                                    std::to_string(dem.height) +
                                    " values but its text holds at most " +
                                    std::to_string((stat.st_size + 1) / 2));
        return;
    }
    // GDAL reads whole blocks, and a pixel-interleaved file's block holds every band: reading
    // band 1 of 63 487 interleaved bands allocated 8.3 GB for a 505-byte file. Such a block is
    // refused when it is more than kMaxInterleavedBlock; any block is checked against memory.
    int block_width = 0, block_height = 0;
    band.GetBlockSize(&block_width, &block_height);
    double block = double(std::max(block_width, 1)) * double(std::max(block_height, 1)) *
                   double(GDALGetDataTypeSizeBytes(band.GetRasterDataType()));
    if (GDALDataset* ds = band.GetDataset()) {
        const char* interleave = ds->GetMetadataItem("INTERLEAVE", "IMAGE_STRUCTURE");
        const int bands = ds->GetRasterCount();
        if (interleave && EQUAL(interleave, "PIXEL") && bands > 1) {
            block *= double(bands);
            constexpr double kMaxInterleavedBlock = 256.0 * 1024 * 1024;
            if (block > kMaxInterleavedBlock)
                throw Error("read", "'" + path + "' interleaves " + std::to_string(bands) +
                                        " bands pixel by pixel: reading band 1 needs blocks of " +
                                        number(block / 1e6) +
                                        " MB; write the band to a file of its own "
                                        "(gdal_translate -b 1)");
        }
    }
    check_memory("one block of '" + path + "'", block, plan ? plan->limit : 0);
    // The last row read back: a file whose data end early fails here, before the grid is
    // allocated and before all the rows before it are read.
    std::vector<double> row(static_cast<std::size_t>(dem.width));
    const GdalErrorCapture errors;
    if (band.RasterIO(GF_Read, 0, dem.height - 1, dem.width, 1, row.data(), dem.width, 1,
                      GDT_Float64, 0, 0) != CE_None)
        throw Error("read", "'" + path + "' declares " + std::to_string(dem.width) + "x" +
                                std::to_string(dem.height) +
                                " pixels but its last row cannot be read; the file is truncated "
                                "or its label declares more than its image holds");
}

void validate_scale(const std::string& path, double scale, double offset) {
    if (!std::isfinite(scale) || !std::isfinite(offset) || scale == 0)
        throw Error("read", "'" + path + "' has scale " + number(scale) + " and offset " +
                                number(offset) +
                                "; the scale must be finite and non-zero, the offset finite");
}

void validate_value_range(const std::string& path, double min_value, double max_value) {
    if (!std::isfinite(min_value) || !std::isfinite(max_value) ||
        std::max(std::abs(min_value), std::abs(max_value)) > kMaxElevationMagnitude)
        throw Error("read", "'" + path + "' has values from " + number(min_value) + " to " +
                                number(max_value) +
                                " m after scale and offset; elevations beyond " +
                                number(kMaxElevationMagnitude) +
                                " m are not a surface (an undeclared NoData value or a wrong "
                                "scale?)");
}

}  // namespace terrain::io
