#pragma once
// Private: the grid a synthetic tile is built on: the tile plus a margin wide enough for the
// largest crater's ejecta, in the equirectangular projection of the tile.
#include "deterministic.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "terrain/synth/crater_field.hpp"

namespace terrain::synth {

// Geometry of the tile and of the extended grid around it.
struct Geometry {
    double radius = kVestaRadius;
    double pixel = 0;   // metres in the projection (x and y)
    double lat_ts = 0;  // latitude of true scale, radians
    double cos_ts = 1;
    double x_left = 0, y_top = 0;  // tile's top-left corner in projected metres
    int margin_x = 0, margin_y = 0;
    int width = 0, height = 0;  // extended grid
    // Projected coordinates of the centre of extended-grid pixel (col,row).
    double x_of(double col) const { return x_left + (col - margin_x + 0.5) * pixel; }
    double y_of(double row) const { return y_top - (row - margin_y + 0.5) * pixel; }
    // Ground metres per projected metre along a parallel at latitude `lat` (radians).
    double east_scale(double lat) const { return std::cos(lat) / cos_ts; }
};

// The geometry of the tile `options` describes (options already validated), its margin
// covering the ejecta of the largest crater. Throws terrain::Error (stage "synth") when the
// extended grid would reach beyond +-85 degrees or hold more than 200 million pixels.
Geometry make_geometry(const VestaTileOptions& options);

// Heights on the extended grid, row-major.
struct Grid {
    int width = 0, height = 0;
    std::vector<double> z;
    double& at(int col, int row) {
        return z[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
                 static_cast<std::size_t>(col)];
    }
    double at(int col, int row) const {
        return z[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
                 static_cast<std::size_t>(col)];
    }
    // Bilinear at a continuous position (pixel centres at +0.5), clamped to the grid.
    double sample(double col, double row) const {
        const double u = std::clamp(col - 0.5, 0.0, double(width - 1));
        const double v = std::clamp(row - 0.5, 0.0, double(height - 1));
        const int i = std::min(static_cast<int>(u), width - 2);
        const int j = std::min(static_cast<int>(v), height - 2);
        const double fu = u - i, fv = v - j;
        const double a = at(i, j) + fu * (at(i + 1, j) - at(i, j));
        const double b = at(i, j + 1) + fu * (at(i + 1, j + 1) - at(i, j + 1));
        return a + fv * (b - a);
    }
};

}  // namespace terrain::synth
