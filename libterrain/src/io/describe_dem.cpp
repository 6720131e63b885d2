#include "terrain/io/describe_dem.hpp"

#include <ogr_spatialref.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>

#include "gdal_support.hpp"

namespace terrain::io {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

bool to_lonlat(OGRCoordinateTransformation& ct, double x, double y, double& lon, double& lat) {
    int ok = 0;
    lon = x;
    lat = y;
    return ct.Transform(1, &lon, &lat, nullptr, &ok) && ok && std::isfinite(lon) &&
           std::isfinite(lat);
}

// Brings `lon` within 180 degrees of `reference`.
double unwrap(double lon, double reference) {
    while (lon - reference > 180) lon -= 360;
    while (lon - reference < -180) lon += 360;
    return lon;
}

}  // namespace

DemDescription describe_dem(const Dem& dem) {
    ensure_gdal_registered();
    const GdalErrorCapture quiet;
    DemDescription d;
    d.width = dem.width;
    d.height = dem.height;
    d.body = dem.body;
    d.crs_wkt = dem.crs_wkt;
    d.elevation = dem.elevation;
    d.elevation_detected = dem.elevation_detected;

    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (double v : dem.values)
        if (!std::isnan(v)) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
            ++d.valid_pixels;
        }
    d.min_value = lo;
    d.max_value = hi;
    const double reference = dem.elevation == ElevationKind::radius ? dem.body.semi_major_axis : 0;
    d.min_height = lo - reference;
    d.max_height = hi - reference;
    d.nodata_fraction = 1.0 - double(d.valid_pixels) / double(dem.values.size());

    const auto& t = dem.transform;
    const double step_x = std::hypot(t[1], t[4]), step_y = std::hypot(t[2], t[5]);
    d.pixel_width_m = step_x;
    d.pixel_height_m = step_y;
    if (dem.crs_wkt.empty()) return d;

    const LonLatTransform tr = make_lonlat_transform(dem.crs_wkt);
    if (tr.geographic) {
        if (const char* name = tr.source->GetName()) d.crs_name = name;
        if (tr.source->IsProjected()) {
            const double unit = tr.source->GetLinearUnits();
            d.pixel_width_m = step_x * unit;
            d.pixel_height_m = step_y * unit;
        }
    }
    if (!tr.to_lonlat) return d;

    // Longitude span along the middle row, unwrapped point after point, so that a global
    // grid reads 360 whatever its longitude origin.
    const int samples = std::min(dem.width, 720);
    const double mid_row = dem.height / 2.0;
    double previous = 0, first = 0, lon = 0, lat = 0;
    bool started = false;
    for (int i = 0; i <= samples; ++i) {
        const double col = dem.width * double(i) / samples;
        const auto [x, y] = dem.map_xy(col, mid_row);
        if (!to_lonlat(*tr.to_lonlat, x, y, lon, lat)) continue;
        lon = started ? unwrap(lon, previous) : lon;
        if (!started) first = lon;
        started = true;
        previous = lon;
    }
    if (!started) return d;
    d.lon_span = previous - first;

    // Bounding box from points along the four edges, longitudes unwrapped around the centre.
    double centre_lon = 0, centre_lat = 0;
    {
        const auto [x, y] = dem.map_xy(dem.width / 2.0, dem.height / 2.0);
        if (!to_lonlat(*tr.to_lonlat, x, y, centre_lon, centre_lat)) centre_lon = first;
    }
    d.lon_min = d.lat_min = std::numeric_limits<double>::infinity();
    d.lon_max = d.lat_max = -d.lon_min;
    const int n = 64;
    for (int i = 0; i <= n; ++i) {
        const double u = double(i) / n;
        const double edge[4][2] = {{u * dem.width, 0},
                                   {u * dem.width, double(dem.height)},
                                   {0, u * dem.height},
                                   {double(dem.width), u * dem.height}};
        for (const auto& p : edge) {
            const auto [x, y] = dem.map_xy(p[0], p[1]);
            if (!to_lonlat(*tr.to_lonlat, x, y, lon, lat)) continue;
            lon = unwrap(lon, centre_lon);
            d.lon_min = std::min(d.lon_min, lon);
            d.lon_max = std::max(d.lon_max, lon);
            d.lat_min = std::min(d.lat_min, lat);
            d.lat_max = std::max(d.lat_max, lat);
        }
    }
    d.has_geographic_extent = std::isfinite(d.lon_min) && std::isfinite(d.lat_min);

    // Global when the row spans 360 degrees to within half a pixel (PDS map scales are
    // rounded: LDEM_4's 1440 pixels of 7580.84 m span 359.998 degrees).
    const double pixel_degrees = std::abs(d.lon_span) / std::max(1, dem.width);
    d.global_longitude = std::abs(d.lon_span) >= 360.0 - 0.5 * pixel_degrees;
    if (d.global_longitude) {
        d.lon_min = first;
        d.lon_max = first + 360.0;
    }
    if (tr.source && tr.source->IsGeographic()) {
        // Degrees to metres at the tile centre, on the body's ellipsoid.
        const double a = dem.body.semi_major_axis, f = dem.body.flattening;
        const double e2 = f * (2 - f), s = std::sin(centre_lat * kDegree);
        const double w = std::sqrt(1 - e2 * s * s);
        const double prime_vertical = a / w, meridional = a * (1 - e2) / (w * w * w);
        d.pixel_width_m = step_x * kDegree * prime_vertical * std::cos(centre_lat * kDegree);
        d.pixel_height_m = step_y * kDegree * meridional;
    }
    return d;
}

}  // namespace terrain::io
