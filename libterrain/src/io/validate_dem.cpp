#include "validate_dem.hpp"
#include "terrain/internal/core/significant.hpp"

#include <cpl_json.h>
#include <cpl_vsi.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "gdal_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/memory_budget.hpp"
#include "terrain/geo/body.hpp"

namespace terrain::io {
namespace {

std::string number(double v) {
    return terrain::detail::significant(v, 6);
}

// Radii and such in full ("1737400", not "1.7374e+06").
std::string metres(double v) {
    return terrain::detail::significant(v, 10);
}

constexpr double kDegreesPerRadian = 180.0 / std::numbers::pi;

// "KEY = value <UNIT>" as the PDS3 label read into `dataset` gives it (GDAL's json:PDS
// metadata: the map projection's keys first, then the image's, then the top level); empty
// when the dataset is not a PDS3 label or the label has no such key.
std::string label_entry(GDALDataset* dataset, const char* key) {
    if (!dataset) return {};
    const GDALDriver* driver = dataset->GetDriver();
    if (!driver || !EQUAL(driver->GetDescription(), "PDS")) return {};
    char** metadata = dataset->GetMetadata("json:PDS");
    if (!metadata || !metadata[0]) return {};
    CPLJSONDocument label;
    if (!label.LoadMemory(std::string(metadata[0]))) return {};
    const CPLJSONObject root = label.GetRoot();
    for (const char* object : {"IMAGE_MAP_PROJECTION", "IMAGE", ""}) {
        const CPLJSONObject parent = *object ? root.GetObj(object) : root;
        if (!parent.IsValid()) continue;
        const CPLJSONObject entry = parent.GetObj(key);
        if (!entry.IsValid()) continue;
        std::string text = entry.ToString(), unit;
        if (entry.GetType() == CPLJSONObject::Type::Object) {
            text = entry.GetObj("value").ToString();
            unit = entry.GetString("unit");
        }
        return std::string(key) + " = " + text + (unit.empty() ? "" : " <" + unit + ">");
    }
    return {};
}

// "the label's KEY = value" or, without a label, `otherwise`.
std::string source_of(GDALDataset* dataset, const char* key, const std::string& otherwise) {
    const std::string entry = label_entry(dataset, key);
    return entry.empty() ? otherwise : "the label's " + entry;
}

// When the CRS gives a known body a radius far from its own (a unit dropped from a label's
// A_AXIS_RADIUS): what to say about it; empty otherwise.
std::string implausible_radius(const Dem& dem, GDALDataset* dataset) {
    const double a = dem.body.semi_major_axis, known = geo::known_body_radius(dem.body.name);
    if (!(known > 0) || (a > known / 1.5 && a < known * 1.5)) return {};
    return source_of(dataset, "A_AXIS_RADIUS", "the CRS") + " gives " + dem.body.name +
           " a radius of " + metres(a) + " m, not about " + metres(known) +
           " m (a unit missing or wrong?)";
}

}  // namespace

void validate_dem_on_body(const std::string& path, const Dem& dem, GDALDataset* dataset) {
    if (!dem.body.has_crs) return;
    const std::string name = "'" + path + "'";
    const double a = dem.body.semi_major_axis;
    if (!(a > 0) || !std::isfinite(a) || !(dem.body.semi_minor_axis() > 0))
        throw Error("read", name + " lies on a body of radius " + metres(a) + " m (" +
                                source_of(dataset, "A_AXIS_RADIUS", "its CRS's ellipsoid") +
                                "); a body needs a positive radius");
    const GridGeoref& g = dem.georef;
    const bool geographic = g.kind == CrsKind::geographic;
    if (!geographic && !g.lonlat) return;  // no longitude/latitude to check (the mesh says so)

    // The pixel centres of the four edges and of a 65 x 65 lattice.
    const int W = dem.width, H = dem.height;
    std::vector<double> x, y;
    std::vector<std::array<int, 2>> pixels;
    const auto add = [&](int col, int row) {
        const auto p = dem.map_xy(col + 0.5, row + 0.5);
        x.push_back(p[0]);
        y.push_back(p[1]);
        pixels.push_back({col, row});
    };
    for (int col = 0; col < W; ++col) add(col, 0), add(col, H - 1);
    for (int row = 1; row + 1 < H; ++row) add(0, row), add(W - 1, row);
    constexpr int kLattice = 64;
    for (int i = 1; i < kLattice; ++i)
        for (int j = 1; j < kLattice; ++j)
            add(int(std::lround(double(W - 1) * i / kLattice)),
                int(std::lround(double(H - 1) * j / kLattice)));
    std::vector<std::uint8_t> ok(x.size(), 1);
    if (!geographic) g.lonlat->to_lonlat(x.size(), x.data(), y.data(), ok.data());
    double lat_lo = 1e300, lat_hi = -1e300;
    std::size_t mapped = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        // Pixel centres outside the projection's valid area may be NoData (the corners of a
        // full-disc orthographic grid): the mesh refuses a valid pixel there.
        if (!ok[i] || !std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
        ++mapped;
        lat_lo = std::min(lat_lo, y[i]);
        lat_hi = std::max(lat_hi, y[i]);
    }
    if (mapped == 0)
        throw Error("read",
                    name + " has no pixel centre its CRS maps to a longitude and latitude " +
                        "(the first at map x, y = " + number(dem.map_xy(0.5, 0.5)[0]) + ", " +
                        number(dem.map_xy(0.5, 0.5)[1]) + "); " +
                        source_of(dataset, "LINE_PROJECTION_OFFSET", "the geotransform's origin") +
                        " or the CRS puts the grid off " + dem.body.name);
    // Half a pixel of slack at the poles (pixel centres of a grid whose edge reaches past the
    // pole by less than a pixel).
    const double step_y = std::hypot(dem.transform[2], dem.transform[5]);
    const double pixel_degrees =
        geographic ? step_y : g.pixel_height_m / dem.body.semi_minor_axis() * kDegreesPerRadian;
    const double slack = 0.5 * pixel_degrees;
    if (lat_lo >= -90 - slack && lat_hi <= 90 + slack) return;

    // Where it comes from: the body's radius, the pixel size or the grid's origin.
    std::string cause = implausible_radius(dem, dataset);
    const double rows_degrees = H * pixel_degrees;
    if (cause.empty() && rows_degrees > 180 + pixel_degrees)
        cause = source_of(dataset, "MAP_SCALE",
                          "the geotransform's pixel height of " + number(g.pixel_height_m) + " m") +
                " makes its " + std::to_string(H) + " rows span " + number(rows_degrees) +
                " degrees of latitude on " + dem.body.name + " (radius " + metres(a) +
                " m), more than pole to pole";
    if (cause.empty()) {
        // The origin: a label's line offset counts pixels of MAP_SCALE; a geotransform's y
        // origin moves with its column term too when it has one.
        const auto top = dem.map_xy(W / 2.0, 0.5);
        std::string origin = label_entry(dataset, "LINE_PROJECTION_OFFSET"), verb = " places";
        if (!origin.empty()) {
            const std::string scale = label_entry(dataset, "MAP_SCALE");
            origin = "the label's " + origin + (scale.empty() ? "" : " (pixels of " + scale + ")");
        } else {
            origin = "the geotransform's y origin of " + number(dem.transform[3]);
            if (dem.transform[4] != 0)
                origin += " and its y step of " + number(dem.transform[4]) + " a column",
                    verb = " place";
        }
        cause = origin + verb +
                " the grid's middle column's first row at map y = " + number(top[1]) + " on " +
                dem.body.name + " (radius " + metres(a) + " m)";
    }
    throw Error("read", name + " has pixel centres at latitudes " + number(lat_lo) + " to " +
                            number(lat_hi) + " degrees, off the body: " + cause +
                            "; a grid past the poles (latitudes beyond +-90) is not a surface");
}

void validate_dem_heights(const std::string& path, const Dem& dem, GDALDataset* dataset,
                          double min_value) {
    if (!dem.body.has_crs || !(dem.body.semi_major_axis > 0)) return;
    const bool radius = dem.elevation == ElevationKind::radius;
    // The smallest distance from the centre: the lowest radius, or the polar radius plus the
    // lowest height.
    const double b = dem.body.semi_minor_axis();
    const double lowest = radius ? min_value : b + min_value;
    if (lowest > 0) return;
    std::string cause = implausible_radius(dem, dataset);
    if (cause.empty()) {
        const std::string offset = label_entry(dataset, "OFFSET"),
                          scale = label_entry(dataset, "SCALING_FACTOR");
        cause = offset.empty() && scale.empty()
                    ? "check the band's scale and offset and its NoData value"
                    : "check the label's " + scale +
                          (scale.empty() || offset.empty() ? "" : " and ") + offset;
    }
    throw Error("read",
                "'" + path + "' has " + (radius ? "radii" : "heights") + " down to " +
                    number(min_value) + " m, " +
                    (radius ? "at or through the centre of " : "at or below the centre of ") +
                    dem.body.name + " (polar radius " + metres(b) + " m): " + cause +
                    "; the body's radius plus the lowest height must stay positive");
}

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
