#pragma once
// How long each region lives in the area hierarchy (docs/segment.md, "Each region's range of
// scales"). A segmentation made with an area threshold A0 is one level of a hierarchy: with a
// larger threshold the simplification goes on, and each region's seed, an extremum of the
// simplified graph, stays an extremum up to some threshold, then is cancelled and its region
// merges into a neighbour. A small crater's floor is cancelled soon after its own area; a
// large basin's floor lives on to thresholds far above the small regions around it.

#include <cstdint>
#include <vector>

#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"
#include "terrain/reeb/simplify.hpp"

namespace terrain::segment {

struct AreaRangeOptions {
    double floor_m2 = 0;     // the threshold the segmentation was made with (m^2, > 0)
    double persistence = 0;  // the persistence threshold it was made with (kept as is)
    double step = 2;         // each level's threshold is the previous one's times this (> 1)
    // A region's range ends where its seed heads more than this times what it headed at the
    // floor (>= 1; infinity: the range ends with the seed only): it has taken in its
    // neighbours.
    double growth = 2;
};

// For each region (seeds[i] is region i + 1's seed node in `graph`, an extremum, as
// grow_regions gives them), the first area threshold of the ladder floor * step^k (k >= 1)
// at which the region ends: its seed is no longer an extremum of its own, or it heads more
// than `growth` times the area it headed at the floor (its node and the regular nodes of its
// arcs: the part of the graph a region grown from it starts with). The graph is simplified
// on and on, each level continuing the one before (as a nested sweep does), with the
// persistence threshold unchanged. When two seeds become one node, the region with the
// lower id keeps it. A region that has not ended once the threshold reaches the mesh's whole
// area (reeb::total_area) gets that area. The graph is consumed (each level frees the one
// before as it goes).
// Deterministic. Throws terrain::Error (stage "segment") for a floor or a step out of range or
// seeds that are not extrema of the graph.
std::vector<double> seed_area_ranges(const TriangleMesh& mesh, reeb::ReebGraph&& graph,
                                     const std::vector<std::int32_t>& seeds,
                                     const AreaRangeOptions& options,
                                     const ProgressFn& progress = {});

}  // namespace terrain::segment
