#pragma once
// Private: the order of events shared by both construction algorithms.

#include <vector>

#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"

namespace terrain::reeb::internal {

// Sorts the vertices into events (nodes) in increasing value: adjacent vertices with equal
// values form one event; other ties go by the plateau's lowest vertex, then by vertex. Fills
// the graph's node_values, node_vertex_offsets, node_vertices and vertex_nodes.
void order_events(const TriangleMesh& mesh, const std::vector<float>& field, ReebGraph& g,
                  const ProgressFn& progress = {});

}  // namespace terrain::reeb::internal
