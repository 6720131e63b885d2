#pragma once
// Private: the possible floors of craters in a region graph (craters.cpp, docs/craters.md).

#include <cstdint>
#include <vector>

#include "terrain/segment/craters.hpp"

namespace terrain::segment::internal {

// Whether region `id` can rim a floor: its mean field (shape index x 100) above
// options.convex_above.
inline bool convex_region(const RegionGraph& graph, std::uint32_t id,
                          const CraterOptions& options) {
    return graph.regions[id - 1].field_mean > options.convex_above;
}

struct FloorCandidate {
    std::vector<std::uint32_t> members;  // its regions, the largest first
    double area_m2 = 0;
    double perimeter_m = 0;  // its outer boundary (the boundaries between members taken out)
};

// In this order: each concave region (mean field below options.concave_below, 3 vertices or
// more); each pair of adjacent concave regions of comparable areas (the smaller at least a
// quarter of the larger) rounder together (area / perimeter^2) than at least one of them (a
// floor cut in two); each group of 3 to 12 adjacent concave regions grown from its largest
// by the neighbour no larger than it that leaves the union roundest, the roundest union met
// when it is rounder than the largest alone (a floor cut in several pieces). Each kept when
// convex neighbours (mean field above options.convex_above) line at least
// options.min_rim_fraction / 2 of its outer boundary. Deterministic: by region id, then by
// edge.
std::vector<FloorCandidate> floor_candidates(const RegionGraph& graph,
                                             const CraterOptions& options);

}  // namespace terrain::segment::internal
