#pragma once
// The colour of a region in the files `terrain segment` writes: labels.tif's attribute table
// and the polygons' "fill".

#include <array>
#include <cstdint>

#include "terrain/segment/regions.hpp"

namespace terrain::io {

// Deterministic, distinct neighbours in the id sequence; id 0 is transparent black.
// {r, g, b, a}.
std::array<std::uint8_t, 4> region_colour(std::uint32_t id);

// The colour of a landform class: the preview's shape-index colour at the class's centre
// (cup blue, saddle near-white, cap red); grey for `unknown`.
std::array<std::uint8_t, 3> landform_colour(segment::Landform landform);

}  // namespace terrain::io
