#pragma once
// A DEM grid as read from a raster: values in metres with scale/offset applied, NoData as
// NaN, the GDAL geotransform and CRS, the body, and whether values are radii or heights.

#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "terrain/core/body.hpp"

namespace terrain {

enum class ElevationKind { height, radius };

const char* to_string(ElevationKind kind);

// GDAL's affine geotransform: x = t[0] + col*t[1] + row*t[2], y = t[3] + col*t[4] + row*t[5],
// with (col,row) = (0,0) the top-left corner of the top-left pixel.
using GeoTransform = std::array<double, 6>;

struct Dem {
    int width = 0;
    int height = 0;
    GeoTransform transform{0, 1, 0, 0, 0, -1};
    bool has_transform = false;  // false: no georeferencing, transform is the default grid
    std::string crs_wkt;         // empty: no CRS, a local metric grid
    Body body;
    ElevationKind elevation = ElevationKind::height;
    bool elevation_detected = true;  // false when the caller forced the kind
    std::vector<double> values;      // row-major, width*height, NaN = NoData
    std::string source;              // the path it was read from
    int band = 1;

    std::size_t size() const { return values.size(); }
    std::size_t index(int col, int row) const {
        return static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
               static_cast<std::size_t>(col);
    }
    double at(int col, int row) const { return values[index(col, row)]; }
    bool valid(int col, int row) const { return !std::isnan(at(col, row)); }

    // Height above the reference body (radius minus the semi-major axis for radius DEMs; a
    // sphere is assumed for that difference, as the PDS products do).
    double height_at(int col, int row) const {
        const double v = at(col, row);
        return elevation == ElevationKind::radius ? v - body.semi_major_axis : v;
    }
    // Georeferenced coordinates of a pixel position (col,row may be fractional: +0.5 = centre).
    std::array<double, 2> map_xy(double col, double row) const {
        return {transform[0] + col * transform[1] + row * transform[2],
                transform[3] + col * transform[4] + row * transform[5]};
    }
};

}  // namespace terrain
