#pragma once
// The colour of a region in the files `terrain segment` writes: labels.tif's attribute table
// and the polygons' "fill".

#include <array>
#include <cstdint>

namespace terrain::io {

// Deterministic, distinct neighbours in the id sequence; id 0 is transparent black.
// {r, g, b, a}.
std::array<std::uint8_t, 4> region_colour(std::uint32_t id);

}  // namespace terrain::io
