#pragma once
// Private: the PROJ-backed LonLatMapping implementations behind GridGeoref (not installed).
// Each thread that calls one gets its own OGR transformation, made from the CRS text the same
// way on every thread, so every thread computes the same doubles.

#include <array>
#include <memory>
#include <string>

#include "terrain/core/georef.hpp"
#include "terrain/internal/geo/ogr_support.hpp"

namespace terrain::geo {

// Map -> lon/lat on the CRS's own geographic CRS. `first` is a transformation already made
// from `crs` (it serves the calling thread); null when the CRS has none.
std::shared_ptr<const LonLatMapping> make_lonlat_mapping(const std::string& crs,
                                                         LonLatTransform first);

// Map -> the outputs' lon/lat (LonLatFrame); null when the CRS has none.
std::shared_ptr<const LonLatMapping> make_output_lonlat_mapping(const std::string& crs, bool earth,
                                                                std::array<double, 2> centre);

}  // namespace terrain::geo
