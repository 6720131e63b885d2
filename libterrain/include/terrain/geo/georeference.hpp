#pragma once
// The geo layer's one service to the rest of the library: what a grid's CRS is and where its
// pixels lie on the body, computed once when the grid is read and handed to the algorithms
// as plain values (terrain/core/georef.hpp). See docs/development.md.

#include <string>

#include "terrain/core/body.hpp"
#include "terrain/core/dem.hpp"
#include "terrain/core/georef.hpp"

namespace terrain::geo {

// The georeference of a width x height grid with geotransform `transform` in the CRS
// `crs_wkt` (any text SetFromUserInput takes; empty: a local grid) on `body`. A CRS that
// cannot be transformed to longitude/latitude gives no mapping and no extent.
GridGeoref georeference(const std::string& crs_wkt, const GeoTransform& transform, int width,
                        int height, const Body& body);

// Sets dem.body from dem.crs_wkt and dem.georef from the CRS, geotransform and size: the one
// call a DEM made in memory needs before it is meshed or segmented (io::read_dem makes it).
// Throws terrain::Error (stage "crs") when the CRS text is not a CRS.
void georeference(Dem& dem);

}  // namespace terrain::geo
