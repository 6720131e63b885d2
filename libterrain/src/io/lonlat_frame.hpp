#pragma once
// Private: the output longitude/latitude frame of the geo layer, for the io writers.

#include "terrain/internal/geo/lonlat_frame.hpp"

namespace terrain::io {

using geo::geojson_crs_name;
using geo::LonLatFrame;

}  // namespace terrain::io
