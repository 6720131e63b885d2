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
    map_srs_ = std::make_unique<OGRSpatialReference>();
    if (map_srs_->SetFromUserInput(dem.crs_wkt.c_str()) != OGRERR_NONE)
        throw Error("write", "cannot read the DEM's CRS");
    map_srs_->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    geographic_ = map_srs_->IsGeographic();
    if (!geographic_) {
        to_map_.reset(OGRCreateCoordinateTransformation(&frame.srs(), map_srs_.get()));
        if (!to_map_) throw Error("write", "cannot transform lon/lat to the DEM's CRS");
    }
}

GlobalOutline::Corners GlobalOutline::corners(const OGRLinearRing& ring, bool densify) const {
    const int n = ring.getNumPoints();
    Corners out;
    auto& [col, row, lon, lat] = out;
    // Pixel coordinates, with every pixel corner along a row between two vertices on it.
    col.reserve(static_cast<std::size_t>(n));
    row.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        const double x = ring.getX(i), y = ring.getY(i);
        const double c = corner(inverse_[0] + x * inverse_[1] + y * inverse_[2]);
        const double r = corner(inverse_[3] + x * inverse_[4] + y * inverse_[5]);
        if (densify && i > 0 && r == row.back() && r == std::round(r)) {
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
    lon.resize(m);
    lat.resize(m);
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
    return out;
}

void GlobalOutline::to_lonlat(OGRLinearRing& ring) const {
    if (ring.getNumPoints() == 0) return;
    auto c = corners(ring, true);
    ring.setPoints(static_cast<int>(c.lon.size()), c.lon.data(), c.lat.data());
}

void GlobalOutline::to_map(OGRLinearRing& ring) const {
    if (ring.getNumPoints() == 0) return;
    // In a geographic CRS the map coordinates are lon/lat: the rows densified as there.
    const auto c = corners(ring, geographic_);
    const std::size_t m = c.col.size();
    std::vector<double> x(m), y(m);
    const double W = dem_.width, H = dem_.height;
    for (std::size_t k = 0; k < m; ++k) {
        const auto xy = dem_.map_xy(c.col[k], c.row[k]);
        x[k] = xy[0];
        y[k] = xy[1];
        const bool seam = c.col[k] == 0 || c.col[k] == W;
        const bool pole = (c.row[k] == 0 || c.row[k] == H) && std::abs(c.lat[k]) == 90.0;
        if (!seam && !pole) continue;
        if (geographic_) {
            // The seam 360 degrees apart.
            const double west = dem_.transform[0];
            if (seam) x[k] = c.col[k] == 0 ? west : west + 360.0;
            if (pole) y[k] = c.lat[k];
            continue;
        }
        const double inside = 1e-9;
        double lon = seam ? (c.col[k] == 0 ? west_ + inside : west_ + 360.0 - inside) : c.lon[k];
        double lat = c.lat[k];
        int ok = 0;
        if (!to_map_->Transform(1, &lon, &lat, nullptr, &ok) || !ok)
            throw Error("write", "the seam or a pole of the DEM has no map coordinates");
        if (seam) x[k] = lon;
        if (pole) y[k] = lat;
    }
    ring.setPoints(static_cast<int>(m), x.data(), y.data());
}

}  // namespace terrain::io
