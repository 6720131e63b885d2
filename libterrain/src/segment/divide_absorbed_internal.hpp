#pragma once
// Private: segment::divide_absorbed with the size of the batches of offers its flooding takes
// on every thread (divide_absorbed.cpp), for tests: SIZE_MAX takes every offer in order on
// one thread, as a flooding one offer at a time does; 1 takes every batch on the threads.

#include <cstddef>

#include "terrain/segment/divide_absorbed.hpp"

namespace terrain::segment::internal {

// Below this many offers a batch is taken in order on the caller's thread: a batch on the
// threads costs a few microseconds to start.
inline constexpr std::size_t kParallelBatch = 64;

DivideCounts divide_absorbed(const TriangleMesh& mesh, const reeb::ReebGraph& graph,
                             const std::vector<float>& field,
                             const std::vector<std::uint8_t>& absorbed, Segmentation& segmentation,
                             const std::vector<std::uint32_t>* finer, const ProgressFn& progress,
                             std::size_t parallel_batch, Residency& memory = all_resident());

}  // namespace terrain::segment::internal
