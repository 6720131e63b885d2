#include "terrain/geo/georeference.hpp"

#include <ogr_spatialref.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "lonlat_mapping.hpp"
#include "terrain/geo/body.hpp"
#include "terrain/internal/geo/ogr_support.hpp"

namespace terrain::geo {
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

std::array<double, 2> map_xy(const GeoTransform& t, double col, double row) {
    return {t[0] + col * t[1] + row * t[2], t[3] + col * t[4] + row * t[5]};
}

// Kind and linear unit of the CRS.
void set_kind(const std::string& crs, GridGeoref& g) {
    OGRSpatialReference srs;
    if (srs.SetFromUserInput(crs.c_str()) != OGRERR_NONE) {
        g.kind = CrsKind::other;
        return;
    }
    g.kind = srs.IsGeographic()  ? CrsKind::geographic
             : srs.IsProjected() ? CrsKind::projected
                                 : CrsKind::other;
    g.linear_unit_m = srs.IsProjected() ? srs.GetLinearUnits() : 1.0;
}

// Extent, global longitude, pole rows and the pixel size in metres, from points along the
// middle row and the four edges.
void set_extent(const Body& body, OGRCoordinateTransformation& ct, bool geographic, GridGeoref& d) {
    const int W = d.width, H = d.height;
    const auto& t = d.transform;
    const double step_x = std::hypot(t[1], t[4]), step_y = std::hypot(t[2], t[5]);

    // Longitude span along the middle row, unwrapped point after point, so that a global
    // grid reads 360 whatever its longitude origin.
    const int samples = std::min(W, 720);
    const double mid_row = H / 2.0;
    double previous = 0, first = 0, lon = 0, lat = 0;
    bool started = false;
    for (int i = 0; i <= samples; ++i) {
        const double col = W * double(i) / samples;
        const auto [x, y] = map_xy(t, col, mid_row);
        if (!to_lonlat(ct, x, y, lon, lat)) continue;
        lon = started ? unwrap(lon, previous) : lon;
        if (!started) first = lon;
        started = true;
        previous = lon;
    }
    if (!started) return;
    d.lon_span = previous - first;

    // Bounding box from points along the four edges, longitudes unwrapped around the centre.
    double centre_lon = 0, centre_lat = 0;
    {
        const auto [x, y] = map_xy(t, W / 2.0, H / 2.0);
        if (!to_lonlat(ct, x, y, centre_lon, centre_lat)) centre_lon = first;
    }
    d.lon_min = d.lat_min = std::numeric_limits<double>::infinity();
    d.lon_max = d.lat_max = -d.lon_min;
    const int n = 64;
    for (int i = 0; i <= n; ++i) {
        const double u = double(i) / n;
        const double edge[4][2] = {{u * W, 0}, {u * W, double(H)}, {0, u * H}, {double(W), u * H}};
        for (const auto& p : edge) {
            const auto [x, y] = map_xy(t, p[0], p[1]);
            if (!to_lonlat(ct, x, y, lon, lat)) continue;
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
    const double pixel_degrees = std::abs(d.lon_span) / std::max(1, W);
    d.global_longitude = std::abs(d.lon_span) >= 360.0 - 0.5 * pixel_degrees;
    if (d.global_longitude) {
        d.lon_min = first;
        d.lon_max = first + 360.0;
        // A pole row: its outer edge within a quarter row of the pole.
        const double row_degrees = (d.lat_max - d.lat_min) / H;
        d.pole_row[0] = d.lat_max > 90.0 - 0.25 * row_degrees;
        d.pole_row[1] = d.lat_min < -90.0 + 0.25 * row_degrees;
    }
    if (geographic) {
        // Degrees to metres at the tile centre, on the body's ellipsoid.
        const double a = body.semi_major_axis, f = body.flattening;
        const double e2 = f * (2 - f), s = std::sin(centre_lat * kDegree);
        const double w = std::sqrt(1 - e2 * s * s);
        const double prime_vertical = a / w, meridional = a * (1 - e2) / (w * w * w);
        d.pixel_width_m = step_x * kDegree * prime_vertical * std::cos(centre_lat * kDegree);
        d.pixel_height_m = step_y * kDegree * meridional;
    }
}

}  // namespace

GridGeoref georeference(const std::string& crs_wkt, const GeoTransform& transform, int width,
                        int height, const Body& body) {
    const GdalErrorCapture quiet;
    GridGeoref g;
    g.crs_wkt = crs_wkt;
    g.transform = transform;
    g.width = width;
    g.height = height;
    const double step_x = std::hypot(transform[1], transform[4]);
    const double step_y = std::hypot(transform[2], transform[5]);
    g.pixel_width_m = step_x;
    g.pixel_height_m = step_y;
    if (crs_wkt.empty()) return g;

    set_kind(crs_wkt, g);
    LonLatTransform tr = make_lonlat_transform(crs_wkt);
    if (tr.geographic) {
        if (const char* name = tr.source->GetName()) g.crs_name = name;
        if (tr.source->IsProjected()) {
            const double unit = tr.source->GetLinearUnits();
            g.pixel_width_m = step_x * unit;
            g.pixel_height_m = step_y * unit;
        }
    }
    if (tr.to_lonlat) {
        const bool geographic = tr.source && tr.source->IsGeographic();
        set_extent(body, *tr.to_lonlat, geographic, g);
    }
    g.lonlat = make_lonlat_mapping(crs_wkt, std::move(tr));
    g.output_lonlat = make_output_lonlat_mapping(crs_wkt, body.name == "Earth",
                                                 map_xy(transform, width / 2.0, height / 2.0));
    return g;
}

void georeference(Dem& dem) {
    dem.body = body_from_crs(dem.crs_wkt);
    dem.georef = georeference(dem.crs_wkt, dem.transform, dem.width, dem.height, dem.body);
}

}  // namespace terrain::geo
