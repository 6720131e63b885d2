#include "pixel_areas.hpp"

#include <GeographicLib/Ellipsoid.hpp>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "terrain/core/error.hpp"

namespace terrain::segment {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr int kStride = 16;

// Longitudes/latitudes of map points, in place; throws when one fails.
void to_lonlat(const LonLatMapping& t, std::vector<double>& x, std::vector<double>& y) {
    if (!t.to_lonlat(x.size(), x.data(), y.data()))
        throw Error("segment",
                    "some pixel corners of the DEM have no longitude/latitude on its body, so "
                    "their areas are unknown; crop the DEM to its projection's valid area");
}

// Node positions 0, stride, 2*stride, ..., last (always included).
std::vector<int> nodes(int count) {
    std::vector<int> out;
    for (int i = 0; i < count - 1; i += kStride) out.push_back(i);
    out.push_back(count - 1);
    return out;
}

// For each index 0..count-1: the lattice segment it falls in and its weight along it.
void segments(const std::vector<int>& node, int count, std::vector<int>& segment,
              std::vector<double>& weight) {
    segment.assign(static_cast<std::size_t>(count), 0);
    weight.assign(static_cast<std::size_t>(count), 0.0);
    if (node.size() < 2) return;
    std::size_t s = 0;
    for (int i = 0; i < count; ++i) {
        while (s + 2 < node.size() && i >= node[s + 1]) ++s;
        segment[static_cast<std::size_t>(i)] = static_cast<int>(s);
        weight[static_cast<std::size_t>(i)] = double(i - node[s]) / double(node[s + 1] - node[s]);
    }
}

}  // namespace

PixelAreas::PixelAreas(const Dem& dem) {
    const auto& t = dem.transform;
    if (dem.crs_wkt.empty()) {
        constant_ = std::abs(t[1] * t[5] - t[2] * t[4]);
        return;
    }
    if (!dem.georef_current())
        throw Error("segment",
                    "the DEM has no georeference for its CRS and grid; call "
                    "geo::georeference(dem)");
    if (!dem.georef.lonlat)
        throw Error("segment", "cannot transform the DEM's CRS to longitude/latitude");
    const LonLatMapping& lonlat = *dem.georef.lonlat;
    const int W = dem.width, H = dem.height;
    const double a = dem.body.semi_major_axis, f = dem.body.flattening;

    // Are rows parallels and columns meridians? Probe a 5 x 5 lattice of pixel corners.
    bool parallels = t[2] == 0 && t[4] == 0;
    std::vector<double> x, y;
    for (int j = 0; j <= 4; ++j)
        for (int i = 0; i <= 4; ++i) {
            const auto p = dem.map_xy(W * i / 4.0, H * j / 4.0);
            x.push_back(p[0]);
            y.push_back(p[1]);
        }
    to_lonlat(lonlat, x, y);
    for (int j = 0; j <= 4 && parallels; ++j)
        for (int i = 0; i <= 4 && parallels; ++i) {
            const std::size_t k = static_cast<std::size_t>(j * 5 + i);
            const std::size_t row0 = static_cast<std::size_t>(j * 5), col0 = std::size_t(i);
            const double dlon = std::remainder(x[k] - x[col0], 360.0);
            parallels = std::abs(y[k] - y[row0]) < 1e-9 && std::abs(dlon) < 1e-9;
        }

    if (parallels) {
        mode_ = Mode::per_row;
        std::vector<double> cx(static_cast<std::size_t>(H) + 2), cy(cx.size());
        for (int r = 0; r <= H; ++r) {
            const auto p = dem.map_xy(0, r);
            cx[std::size_t(r)] = p[0];
            cy[std::size_t(r)] = p[1];
        }
        const auto p = dem.map_xy(1, 0);
        cx.back() = p[0];
        cy.back() = p[1];
        to_lonlat(lonlat, cx, cy);
        const double dlon = std::abs(std::remainder(cx.back() - cx[0], 360.0)) * kDegree;
        const GeographicLib::Ellipsoid ellipsoid(a, f);
        // Area between the equator and latitude phi per radian of longitude: Rq^2 sin(xi).
        const double rq2 = ellipsoid.Area() / (4 * std::numbers::pi);
        auto band = [&](double lat) {
            const double phi = std::max(-90.0, std::min(90.0, lat));
            return rq2 * std::sin(ellipsoid.AuthalicLatitude(phi) * kDegree);
        };
        rows_.resize(static_cast<std::size_t>(H));
        for (int r = 0; r < H; ++r)
            rows_[std::size_t(r)] =
                dlon * std::abs(band(cy[std::size_t(r) + 1]) - band(cy[std::size_t(r)]));
        return;
    }

    mode_ = Mode::lattice;
    node_cols_ = nodes(W);
    node_rows_ = nodes(H);
    segments(node_cols_, W, col_segment_, col_weight_);
    segments(node_rows_, H, row_segment_, row_weight_);
    // The four corners of every node pixel, counter-clockwise in map coordinates.
    x.clear();
    y.clear();
    const double corner[4][2] = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
    for (int r : node_rows_)
        for (int c : node_cols_)
            for (const auto& k : corner) {
                const auto p = dem.map_xy(c + k[0], r + k[1]);
                x.push_back(p[0]);
                y.push_back(p[1]);
            }
    to_lonlat(lonlat, x, y);
    const GeographicLib::Geodesic geodesic(a, f);
    node_areas_.resize(x.size() / 4);
    for (std::size_t n = 0; n < node_areas_.size(); ++n) {
        GeographicLib::PolygonArea polygon(geodesic);
        for (std::size_t k = 0; k < 4; ++k) polygon.AddPoint(y[4 * n + k], x[4 * n + k]);
        double perimeter = 0, area = 0;
        polygon.Compute(false, true, perimeter, area);
        node_areas_[n] = std::abs(area);
    }
}

double PixelAreas::interpolate(int col, int row) const {
    const std::size_t nc = node_cols_.size(), nr = node_rows_.size();
    const auto c = static_cast<std::size_t>(col), r = static_cast<std::size_t>(row);
    const auto i = static_cast<std::size_t>(col_segment_[c]);
    const auto j = static_cast<std::size_t>(row_segment_[r]);
    const std::size_t i1 = std::min(i + 1, nc - 1), j1 = std::min(j + 1, nr - 1);
    const double u = col_weight_[c], v = row_weight_[r];
    auto at = [&](std::size_t jj, std::size_t ii) { return node_areas_[jj * nc + ii]; };
    return (1 - v) * ((1 - u) * at(j, i) + u * at(j, i1)) +
           v * ((1 - u) * at(j1, i) + u * at(j1, i1));
}

}  // namespace terrain::segment
