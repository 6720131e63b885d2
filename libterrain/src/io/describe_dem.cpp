#include "terrain/io/describe_dem.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "terrain/geo/georeference.hpp"

namespace terrain::io {

DemDescription describe_dem(const Dem& dem) {
    DemDescription d;
    d.width = dem.width;
    d.height = dem.height;
    d.body = dem.body;
    d.crs_wkt = dem.crs_wkt;
    d.elevation = dem.elevation;
    d.elevation_detected = dem.elevation_detected;

    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (double v : dem.values)
        if (!std::isnan(v)) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
            ++d.valid_pixels;
        }
    d.min_value = lo;
    d.max_value = hi;
    const double reference = dem.elevation == ElevationKind::radius ? dem.body.semi_major_axis : 0;
    d.min_height = lo - reference;
    d.max_height = hi - reference;
    d.nodata_fraction = 1.0 - double(d.valid_pixels) / double(dem.values.size());

    // What the geo layer found when the DEM was read (or now, for a grid changed since).
    const GridGeoref g =
        dem.georef_current() && !dem.georef.crs_wkt.empty()
            ? dem.georef
            : geo::georeference(dem.crs_wkt, dem.transform, dem.width, dem.height, dem.body);
    d.crs_name = g.crs_name;
    d.pixel_width_m = g.pixel_width_m;
    d.pixel_height_m = g.pixel_height_m;
    d.has_geographic_extent = g.has_geographic_extent;
    d.lon_min = g.lon_min;
    d.lon_max = g.lon_max;
    d.lat_min = g.lat_min;
    d.lat_max = g.lat_max;
    d.lon_span = g.lon_span;
    d.global_longitude = g.global_longitude;
    return d;
}

}  // namespace terrain::io
