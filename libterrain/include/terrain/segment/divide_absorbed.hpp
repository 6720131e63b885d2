#pragma once
// Absorbed vertices divided among the regions around them (docs/segment.md, "Absorbed
// vertices"). The paper's simplification hands the vertices of every cancelled node to the
// node that survives, at that node's value; the paper's growing then moves them as one unit.
// On noisy closed or large surfaces the cancellations chain, and one surviving node can hold
// most of the body (98.6 % of the global Moon), which becomes one region. Here the regions
// grown on the simplified graph keep what is their own (the vertices of surviving nodes), and
// the absorbed vertices are flooded back from the regions' edges by their original values:
// each goes to a region near it whose mean value it is close to.

#include <cstdint>
#include <functional>
#include <vector>

#include "terrain/core/progress.hpp"
#include "terrain/core/residency.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"
#include "terrain/segment/grow_regions.hpp"

namespace terrain::segment {

struct DivideCounts {
    std::size_t absorbed = 0;    // vertices the simplification had absorbed
    std::size_t detached = 0;    // region vertices cut off from their seed once those left
    std::size_t relabelled = 0;  // of both, those that ended in another region than before
};

// `segmentation` was grown on `graph` (the simplified graph); `field` is the field before the
// simplification and `absorbed` the simplification's per-vertex flags (reeb::SimplifyResult).
// Every absorbed vertex leaves its region; so does any vertex of a region no longer connected
// to the region's seed without them; then all of them join the regions again along the
// cheapest paths from the regions' edges, a path into region r costing at each vertex u
// |field(u) - mean of r| plus 1 % of the field's range per mean edge length (ties by vertex,
// then region). The region count and seeds are unchanged; every region
// stays connected on the mesh (each vertex joins next to a vertex of its region); every vertex
// keeps a region. Deterministic, O(n log n). Throws terrain::Error when the sizes disagree.
// `finer`: the labels of a finer scale of a sweep whose graph this one's continues. Before the
// flooding, the absorbed vertices of each finer region go to the region most of that finer
// region's other vertices are in here (then the connectivity rule above applies), so that
// regions nest in those of coarser scales where the graph allows it.
// `memory` is told Stage::flood once the graph and the absorbed flags are read no more (the
// caller may free them; the field and the mesh's positions are read from then on, the labels
// as grown not until Stage::relabel, after the flooding).
DivideCounts divide_absorbed(const TriangleMesh& mesh, const reeb::ReebGraph& graph,
                             const std::vector<float>& field,
                             const std::vector<std::uint8_t>& absorbed, Segmentation& segmentation,
                             const std::vector<std::uint32_t>* finer = nullptr,
                             const ProgressFn& progress = {}, Residency& memory = all_resident());

}  // namespace terrain::segment
