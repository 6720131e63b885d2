#pragma once
// Where a grid's pixels lie on its body, as plain values: the kind of CRS and its unit, the
// geographic extent, whether the grid closes around the body, and the mapping of map
// coordinates to longitude/latitude. The geo layer computes it once, when the grid is read
// (terrain/geo/georeference.hpp); the algorithms only read it. See docs/development.md.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace terrain {

// GDAL's affine geotransform: x = t[0] + col*t[1] + row*t[2], y = t[3] + col*t[4] + row*t[5],
// with (col,row) = (0,0) the top-left corner of the top-left pixel.
using GeoTransform = std::array<double, 6>;

// none: a local metric grid; other: a CRS neither geographic nor projected (geocentric...).
enum class CrsKind { none, geographic, projected, other };

const char* to_string(CrsKind kind);

// Map coordinates of a grid's CRS to longitude and latitude in degrees (longitude first) on a
// geographic CRS of the same body. Implementations may be called from several threads at
// once; copies of a Dem share one.
class LonLatMapping {
  public:
    virtual ~LonLatMapping() = default;

    // In place: x, y hold `count` map points on entry and longitudes, latitudes on return.
    // ok (null, or `count` entries) receives 1 for each point with a finite longitude and
    // latitude, 0 for the others (outside the projection's valid area). True when every
    // point has one.
    virtual bool to_lonlat(std::size_t count, double* x, double* y, std::uint8_t* ok) const = 0;
    bool to_lonlat(std::size_t count, double* x, double* y) const {
        return to_lonlat(count, x, y, nullptr);
    }

    // The geographic CRS of the longitudes and latitudes, as single-line WKT2.
    virtual std::string lonlat_crs_wkt() const = 0;
};

struct GridGeoref {
    // What it was computed from: the CRS text, the geotransform and the grid's size.
    std::string crs_wkt;
    GeoTransform transform{0, 1, 0, 0, 0, -1};
    int width = 0, height = 0;

    CrsKind kind = CrsKind::none;
    std::string crs_name;       // the CRS's name; empty for no CRS
    double linear_unit_m = 1;   // metres per map unit of a projected CRS; 1 otherwise
    double pixel_width_m = 0;   // pixel size at the grid's centre, on the body
    double pixel_height_m = 0;  // (a grid without CRS: the geotransform's steps)

    bool has_geographic_extent = false;                         // false for a local grid
    double lon_min = 0, lon_max = 0, lat_min = 0, lat_max = 0;  // degrees
    double lon_span = 0;            // degrees of longitude along the middle row
    bool global_longitude = false;  // the rows go 360 degrees round: the seam closes
    // A global grid whose first (north) / last (south) row touches a pole: its outer edge
    // lies within a quarter row of it.
    std::array<bool, 2> pole_row{false, false};

    // Map -> longitude/latitude on the CRS's own geographic CRS (the base of a projected
    // CRS): what the mesh and the pixel areas use. Null without CRS or transformation.
    std::shared_ptr<const LonLatMapping> lonlat;
    // Map -> the longitude/latitude of the outputs: EPSG:4326 on Earth (RFC 7946), the
    // CRS's geographic CRS elsewhere, longitudes kept within 180 degrees of the grid's centre
    // (a global 0..360 grid keeps 0..360). Null without CRS or transformation.
    std::shared_ptr<const LonLatMapping> output_lonlat;
};

}  // namespace terrain
