#pragma once
// A DEM grid as read from a raster: values in metres with scale/offset applied, NoData as
// NaN, the GDAL geotransform and CRS, the body, whether values are radii or heights, and the
// georeference the geo layer computed from the CRS (terrain/geo/georeference.hpp).

#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "terrain/core/body.hpp"
#include "terrain/core/georef.hpp"
#include "terrain/core/names.hpp"

namespace terrain {

enum class ElevationKind { height, radius };

// The names --elevation (and the Python module's elevation=) give the kinds, besides "auto".
inline constexpr Named<ElevationKind> kElevationNames[] = {
    {"radius", ElevationKind::radius},
    {"height", ElevationKind::height},
};
const char* to_string(ElevationKind kind);

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
    // Set by io::read_dem, or by geo::georeference(dem) for a grid made in memory; a grid
    // without CRS needs none.
    GridGeoref georef;

    // True when `georef` describes this grid: computed from its CRS, geotransform and size (a
    // grid without CRS: any georeference of no CRS, the default one included).
    bool georef_current() const;

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
