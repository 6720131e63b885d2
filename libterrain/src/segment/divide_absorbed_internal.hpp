#pragma once
// Private: segment::divide_absorbed with the number of parts of the vertices its flooding
// takes on the threads (flooding.hpp), for tests: 1 floods in order on one thread, k in k
// parts, 0 as divide_absorbed chooses.

#include <cstddef>

#include "terrain/segment/divide_absorbed.hpp"

namespace terrain::segment::internal {

// With this many vertices or more, the flooding goes in parts: kPartsPerThread a thread (so
// that a thread that finishes its parts first takes another's), at most kMostParts. Below,
// the rounds' starts on the threads cost more than they save.
inline constexpr std::size_t kPartsFrom = std::size_t{1} << 18;
inline constexpr std::size_t kPartsPerThread = 8;
inline constexpr std::size_t kMostParts = 64;

DivideCounts divide_absorbed(const TriangleMesh& mesh, const reeb::ReebGraph& graph,
                             const std::vector<float>& field,
                             const std::vector<std::uint8_t>& absorbed, Segmentation& segmentation,
                             const std::vector<std::uint32_t>* finer, const ProgressFn& progress,
                             std::size_t parts, Residency& memory = all_resident());

}  // namespace terrain::segment::internal
