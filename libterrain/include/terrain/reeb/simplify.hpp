#pragma once
// Topological simplification of a Reeb graph by cancelling critical-node pairs (paper s.3.2,
// METHOD.md s.4). An arc is a candidate when one end is an extremum, it is not one of several
// arcs between the same two nodes, and its persistence or its area ratio is below the
// threshold. Candidates are cancelled from the lowest persistence up (ties by arc id):
// saddle-extremum (the extremum and the arc are absorbed into the saddle) or
// extremum-extremum (both become one node at the midpoint value). The vertices' values are
// rewritten so that the field and the simplified graph agree.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"

namespace terrain::reeb {

struct SimplifyOptions {
    double persistence = 0;  // cancel arcs with |f(n1) - f(n2)| below this (field units)
    double area_ratio = 0;   // percent: cancel arcs whose area ratio is below area_ratio/100
    // Whether SimplifyResult::field is made (4 bytes a vertex). The growing reads the
    // simplified graph's node values and the field as computed, never the rewritten one:
    // pipeline::segment asks for it only when it writes it.
    bool rewrite_field = true;
};

struct SimplifyResult {
    ReebGraph graph;           // the simplified graph, nodes renumbered
    std::vector<float> field;  // the rewritten field: each vertex takes its node's value
                               // (empty unless SimplifyOptions::rewrite_field)
    // Per vertex, 1 when a cancellation handed its original node to another node (an extremum
    // absorbed into a saddle, regular nodes left outside their arc's new range, ...): these
    // vertices sit in a node that is not their own, at a value that is not theirs. The
    // growing can give them back to the regions around by their original values
    // (segment::divide_absorbed).
    std::vector<std::uint8_t> absorbed;
    std::size_t saddle_extremum = 0, extremum_extremum = 0;  // cancellations done
    // What the cancellations did besides. Each node made regular merges its two arcs into one,
    // so the graph loses (cancellations + made_regular) critical nodes and as many arcs.
    std::size_t made_regular = 0;  // critical nodes left with one arc below and one above
    std::size_t arcs_turned = 0;   // arcs whose far end was left on the other side of a moved
                                   // end's value, so that their ends swapped
    std::size_t turned_made_regular = 0;   // of made_regular: far ends of turned arcs
    std::size_t turned_made_extremum = 0;  // far ends of turned arcs left extrema (their
                                           // arcs are new candidates)
    // Candidates that waited because their cancellation would have turned both arcs of a
    // loop around (the loop would have closed in the rewritten field); each wait counts.
    std::size_t loop_waits = 0;
    // Bytes of the working graph and the queue at the end of the cancellations (their arc
    // runs never shrink, so this is their peak).
    std::size_t working_bytes = 0;
};

// Throws terrain::Error (stage "simplify") for a negative or non-finite threshold, or an area
// ratio above 100 percent.
void check_simplify_options(const SimplifyOptions& options);

// Throws as check_simplify_options does.
SimplifyResult simplify(const TriangleMesh& mesh, const ReebGraph& graph,
                        const SimplifyOptions& options, const ProgressFn& progress = {});
// The same, taking the graph: its arc lists and kinds are freed once the working copy is
// made (less memory at the peak), and the rest (its nodes' values, vertex lists and links)
// once the result is written: the graph is left empty, and what follows the simplification
// (growing, dividing, the region graph) runs without it.
// `memory`: told the stages entered (Stage::simplify_nodes while the working copy sums the
// nodes' areas, the last read of the mesh's vertex areas; Stage::simplify_arcs for the copy of
// the arcs, the peak of its memory, and the cancellations; Stage::simplify_output), and given
// to stash from the copy to the output, which reads them again: the graph's vertices' nodes (4
// bytes a vertex, from which the output makes the nodes' vertex lists again when the graph's
// lists were ascending, as build_reeb_graph makes them) and the working copy's new numbers of
// the graph's nodes (4 bytes a node).
SimplifyResult simplify(const TriangleMesh& mesh, ReebGraph&& graph, const SimplifyOptions& options,
                        const ProgressFn& progress = {}, Residency& memory = all_resident());

// Persistence and area ratio (a fraction, not percent) of each arc of a graph on its mesh.
struct ArcMetrics {
    std::vector<float> persistence;
    std::vector<double> area_ratio;
};
ArcMetrics arc_metrics(const TriangleMesh& mesh, const ReebGraph& graph);

// The area that area ratios divide by: the sum of the mesh's vertex areas (1 per vertex on a
// mesh without areas), in the mesh's units squared (m^2 on DEM meshes).
double total_area(const TriangleMesh& mesh);

// The area-ratio threshold (percent) equivalent to an area threshold on this mesh: an arc's
// area ratio is its area over total_area(mesh), so "area below min_area" is "area ratio below
// 100 * min_area / total_area(mesh) percent" (equal up to rounding). Capped at 100 percent
// (a min_area at or above the whole surface cancels as far as the area ratio can).
double area_ratio_for_area(const TriangleMesh& mesh, double min_area);

}  // namespace terrain::reeb
