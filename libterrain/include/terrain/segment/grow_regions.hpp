#pragma once
// Region growing from the extrema of a (simplified) Reeb graph (paper s.3.3, METHOD.md s.5).
// Every extremum node seeds a region; other nodes join, cheapest (node, region) pair first,
// a node joining only a region one of its vertices touches on the mesh.
//   standard cost: |mean_A(f, R) - f(u)|, the region's area-weighted mean;
//   graph cost:    the same, only for nodes with a Reeb-graph neighbour already in a region,
//                  plus the saddle penalty while more than one of u's branches is unassigned.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/names.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"

namespace terrain::segment {

enum class GrowCost { graph, standard };

// The costs' names (--cost, run.json).
inline constexpr Named<GrowCost> kGrowCostNames[] = {
    {"graph", GrowCost::graph},
    {"standard", GrowCost::standard},
};
// "graph" or "standard"; throws terrain::Error (stage "segment") for anything else.
GrowCost parse_grow_cost(const std::string& name);
const char* to_string(GrowCost cost);

struct GrowOptions {
    GrowCost cost = GrowCost::graph;
    double saddle_penalty = 20;  // lambda, in field units
    // A node holding at least 1/walk_share of the vertices has them visited in vertex order
    // (a pass over vertex_nodes) rather than in its list's order (docs/segment.md); 0: never.
    // Speed only: the regions are the same whatever it is.
    std::size_t walk_share = 64;
};

struct Segmentation {
    std::vector<std::uint32_t> labels;  // per vertex, 1..region_count
    std::uint32_t region_count = 0;
    std::vector<std::int32_t> seeds;  // seed node of each region (index label-1)
    // Nodes that no region could reach under the graph constraint and joined under the
    // standard cost instead (0 in every case we have seen; reported, never hidden).
    std::size_t relaxed_nodes = 0;
};

// Regions are numbered by their seed's lowest vertex index (row-major for DEM meshes), so the
// numbering is stable. Deterministic; O(n log n).
Segmentation grow_regions(const TriangleMesh& mesh, const reeb::ReebGraph& graph,
                          const GrowOptions& options = {}, const ProgressFn& progress = {});

}  // namespace terrain::segment
