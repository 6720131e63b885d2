#pragma once
// What `terrain info` reports about a DEM: size, pixel size in metres, CRS, body, elevation
// kind and range, NoData fraction, geographic coverage.

#include <string>

#include "terrain/core/dem.hpp"

namespace terrain::io {

struct DemDescription {
    int width = 0, height = 0;
    double pixel_width_m = 0, pixel_height_m = 0;  // at the tile centre, on the body
    std::string crs_name;                          // empty for no CRS
    std::string crs_wkt;
    Body body;
    ElevationKind elevation = ElevationKind::height;
    bool elevation_detected = true;
    double min_value = 0, max_value = 0;    // as stored (radius or height), metres
    double min_height = 0, max_height = 0;  // above the reference body, metres
    std::size_t valid_pixels = 0;
    double nodata_fraction = 0;
    bool has_geographic_extent = false;                         // false for a local grid
    double lon_min = 0, lon_max = 0, lat_min = 0, lat_max = 0;  // degrees
    double lon_span = 0;            // degrees of longitude along the middle row
    bool global_longitude = false;  // covers 360 degrees: the seam closes
};

DemDescription describe_dem(const Dem& dem);

}  // namespace terrain::io
