#pragma once
// The Reeb graph of a piecewise-linear scalar field on a triangle mesh (paper s.3.1,
// METHOD.md s.3). Every mesh vertex belongs to exactly one node: adjacent vertices with equal
// values form one node. Critical nodes (extrema and saddles) are the graph's nodes; regular
// nodes sit, sorted by value, in the list of the arc they lie on. Parallel arcs between the
// same two nodes are kept: they are the graph's loops.
//
// Built by one of two exact algorithms (docs/reeb.md), both giving the same graph: the contour
// tree (join and split trees merged) when every component of the mesh is a disk or a sphere,
// else a sweep in increasing value that tracks the level-set contours through the triangles
// they cross, for any 2-manifold mesh with or without boundary, of any genus.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "terrain/core/progress.hpp"
#include "terrain/core/residency.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::reeb {

// The node's place in the graph: by its arcs below (down-degree) and above (up-degree).
enum class NodeKind : std::uint8_t {
    regular,  // one arc below, one above: sits inside an arc
    minimum,  // no arc below
    maximum,  // no arc above
    saddle,   // arcs below and above, three or more in all
};
const char* to_string(NodeKind kind);

// The paper's link classification (s.2.1), from the numbers of connected components of the
// node's lower and upper links.
enum class LinkClass : std::uint8_t {
    regular,
    morse_minimum,
    degenerate_minimum,
    morse_maximum,
    degenerate_maximum,
    morse_saddle,
    degenerate_saddle,
    asymmetric_saddle,
};
const char* to_string(LinkClass link_class);
LinkClass classify_link(int lower_components, int upper_components);

struct ReebGraph {
    // Nodes, critical and regular. node_vertices[node_vertex_offsets[n] ..
    // node_vertex_offsets[n+1]) are the vertices of node n, all with value node_values[n].
    std::vector<float> node_values;
    std::vector<NodeKind> node_kinds;
    // Components of a critical node's lower and upper links (capped at 255); 1 and 1 for
    // regular nodes.
    std::vector<std::uint8_t> node_lower_links;
    std::vector<std::uint8_t> node_upper_links;
    std::vector<std::int32_t> node_vertex_offsets;
    std::vector<std::int32_t> node_vertices;
    std::vector<std::int32_t> vertex_nodes;  // the node of each mesh vertex
    std::vector<std::int32_t> node_arcs;     // a regular node's arc; -1 for critical nodes

    // Arcs between critical nodes, {lower-valued end, upper-valued end}; the regular nodes of
    // arc a are arc_nodes[arc_offsets[a] .. arc_offsets[a+1]), from the lower end upwards.
    std::vector<std::array<std::int32_t, 2>> arcs;
    std::vector<std::int32_t> arc_offsets;
    std::vector<std::int32_t> arc_nodes;

    std::size_t node_count() const { return node_values.size(); }
    std::size_t arc_count() const { return arcs.size(); }
    bool is_critical(std::int32_t node) const {
        return node_kinds[static_cast<std::size_t>(node)] != NodeKind::regular;
    }
    bool is_extremum(std::int32_t node) const {
        const NodeKind k = node_kinds[static_cast<std::size_t>(node)];
        return k == NodeKind::minimum || k == NodeKind::maximum;
    }
    std::size_t memory_bytes() const;
};

// Counts that describe a graph.
struct ReebSummary {
    std::size_t nodes = 0;  // all nodes, regular included
    std::size_t critical = 0, minima = 0, maxima = 0, saddles = 0;
    std::size_t arcs = 0;
    std::size_t components = 0;  // connected components of the graph
    std::size_t loops = 0;       // independent cycles: arcs - critical + components
    // Sum over critical nodes of the PL index (Banchoff): 1 for an extremum, else
    // 1 - (lower + upper link components)/2; equals the Euler characteristic on a closed mesh
    // when no plateau is a critical node.
    double index_sum = 0;
};
ReebSummary summarize(const ReebGraph& graph, const ProgressFn& progress = {});

// Arcs incident to each critical node, CSR over nodes (regular nodes have none).
struct NodeArcs {
    std::vector<std::int32_t> offsets;  // node_count + 1
    std::vector<std::int32_t> arcs;
    std::size_t degree(std::int32_t node) const {
        return static_cast<std::size_t>(offsets[static_cast<std::size_t>(node) + 1] -
                                        offsets[static_cast<std::size_t>(node)]);
    }
};
NodeArcs node_arcs(const ReebGraph& graph);

enum class ReebAlgorithm {
    automatic,     // contour tree when every component is a disk or a sphere, else sweep
    sweep,         // contour tracking: any genus, any number of holes
    contour_tree,  // join and split trees merged: only for disks and spheres (no loops)
};

struct ReebOptions {
    ReebAlgorithm algorithm = ReebAlgorithm::automatic;
    // The caller has found the mesh a tree (reeb_is_tree): one with handles or holes is then
    // an error.
    bool known_tree = false;
    // Told the stages entered (Stage::reeb_events to reeb_loops) and given the graph's vertex
    // lists, vertices' nodes and node values to stash through the contour tree's join and
    // split sweeps (its peak of memory), which do not read them. Null: all stay in memory.
    Residency* memory = nullptr;
};

// True when every connected component of the mesh is a disk or a sphere, so that the Reeb
// graph of any field on it is a tree. Reports its progress ("reeb: loops", 0 to 1).
bool reeb_is_tree(const TriangleMesh& mesh, const ProgressFn& progress = {});

// The Reeb graph of `field` (one value per mesh vertex, no NaN) on a consistently oriented
// 2-manifold mesh, as dem_to_mesh and read_mesh make them (the contour tree reads each
// vertex's link in counter-clockwise order; the sweep checks the orientation and throws).
// Both algorithms give the same graph. Deterministic: ties between equal values that are not
// adjacent are broken by vertex index. Throws terrain::Error when the field has the wrong size
// or NaN values, or when the contour tree is asked for on a mesh with loops.
ReebGraph build_reeb_graph(const TriangleMesh& mesh, const std::vector<float>& field,
                           const ReebOptions& options = {}, const ProgressFn& progress = {});

// Checks the graph's invariants against its mesh and field: every vertex in exactly one node,
// node values equal their vertices' values, arcs go upwards with sorted regular nodes, node
// kinds agree with the arcs. Returns an empty string when all hold, else the first failure.
std::string check_reeb_graph(const ReebGraph& graph, const std::vector<float>& field);

}  // namespace terrain::reeb
