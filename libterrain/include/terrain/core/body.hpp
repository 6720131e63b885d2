#pragma once
// The body a DEM lies on (Earth, Moon, Mars, Vesta, ...) and its reference ellipsoid. The geo
// layer identifies it from the raster's CRS (terrain/geo/body.hpp). See
// docs/bodies-and-elevation.md.

#include <string>

namespace terrain {

struct Body {
    std::string name;            // "Moon", "Mars", ...; "unknown" or "none" otherwise
    double semi_major_axis = 0;  // metres; 0 for a local grid with no CRS
    double flattening = 0;       // (a - b) / a; 0 for a sphere
    bool has_crs = false;        // false: a local metric grid, no body

    double semi_minor_axis() const { return semi_major_axis * (1 - flattening); }
    bool is_local_grid() const { return !has_crs; }
};

}  // namespace terrain
