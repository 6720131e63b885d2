#include "global_outline.hpp"

#include <gdal.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "terrain/core/error.hpp"

namespace terrain::io {
namespace {

// A pixel coordinate of a polygon vertex: GDALPolygonize puts vertices on pixel corners, so
// it is an integer up to rounding.
double corner(double v) {
    const double r = std::round(v);
    return std::abs(v - r) < 1e-6 ? r : v;
}

}  // namespace

bool GlobalOutline::applies(const Dem& dem) {
    return !dem.crs_wkt.empty() && dem.georef.global_longitude;
}

GlobalOutline::GlobalOutline(const Dem& dem, const LonLatFrame& frame) : dem_(dem), frame_(frame) {
    if (!GDALInvGeoTransform(const_cast<double*>(dem.transform.data()), inverse_))
        throw Error("write", "the DEM's geotransform cannot be inverted");
    // The frame keeps longitudes within 180 degrees of the grid's centre: the centre meridian
    // itself comes back as it is.
    auto [x, y] = dem.map_xy(dem.width / 2.0, dem.height / 2.0);
    if (!frame.transform(1, &x, &y)) throw Error("write", "the DEM's centre has no longitude");
    west_ = x - 180.0;
}

void GlobalOutline::to_lonlat(OGRLinearRing& ring) const {
    const int n = ring.getNumPoints();
    if (n == 0) return;
    // Pixel coordinates, with every pixel corner along a row between two vertices on it.
    std::vector<double> col, row;
    col.reserve(static_cast<std::size_t>(n));
    row.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        const double x = ring.getX(i), y = ring.getY(i);
        const double c = corner(inverse_[0] + x * inverse_[1] + y * inverse_[2]);
        const double r = corner(inverse_[3] + x * inverse_[4] + y * inverse_[5]);
        if (i > 0 && r == row.back() && r == std::round(r)) {
            const double c0 = col.back();
            const int steps = static_cast<int>(std::abs(c - c0));
            const double step = c > c0 ? 1.0 : -1.0;
            for (int k = 1; k < steps; ++k) {
                col.push_back(c0 + k * step);
                row.push_back(r);
            }
        }
        col.push_back(c);
        row.push_back(r);
    }
    const std::size_t m = col.size();
    std::vector<double> lon(m), lat(m);
    for (std::size_t i = 0; i < m; ++i) {
        const auto xy = dem_.map_xy(col[i], row[i]);
        lon[i] = xy[0];
        lat[i] = xy[1];
    }
    if (!frame_.transform(m, lon.data(), lat.data()))
        throw Error("write", "a region's outline has no longitude/latitude");
    const double quarter_row = 0.25 * 180.0 / dem_.height;
    for (std::size_t i = 0; i < m; ++i) {
        // The seam: the west edge at west(), the east edge 360 degrees on; in between,
        // longitudes within the grid's range.
        if (col[i] == 0) {
            lon[i] = west_;
        } else if (col[i] == dem_.width) {
            lon[i] = west_ + 360.0;
        } else {
            lon[i] = west_ + std::fmod(std::fmod(lon[i] - west_, 360.0) + 360.0, 360.0);
        }
        // The poles: the outer edge of a pole row on the pole, and no latitude beyond one.
        if ((row[i] == 0 || row[i] == dem_.height) && 90.0 - std::abs(lat[i]) < quarter_row)
            lat[i] = std::copysign(90.0, lat[i]);
        lat[i] = std::clamp(lat[i], -90.0, 90.0);
    }
    ring.setPoints(static_cast<int>(m), lon.data(), lat.data());
}

}  // namespace terrain::io
