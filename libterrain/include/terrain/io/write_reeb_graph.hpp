#pragma once
// The Reeb graph as files: JSON (../shared/CLI.md's `reeb` format) and GraphViz DOT.
// Atomic (a temporary sibling renamed when complete); throw terrain::Error (stage "write").

#include <string>
#include <vector>

#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"

namespace terrain::io {

// Extra key/value pairs written under "parameters" (already formatted as JSON values).
using JsonParameters = std::vector<std::pair<std::string, std::string>>;

// {"nodes": [critical nodes: id, type, class, value, vertex_count, lower_links, upper_links,
//   degree, vertex (the node's first vertex)],
//  "arcs": [id, from (lower node), to (upper node), regular_vertex_count, persistence,
//   area_ratio (percent)],
//  "mesh": {vertices, faces, boundary_edges, euler_characteristic},
//  "summary": {...}, "parameters": {...}}
// Node ids are the critical nodes numbered 0.. in the graph's order. Atomic; refuses an
// existing file unless overwrite.
void write_reeb_json(const reeb::ReebGraph& graph, const TriangleMesh& mesh,
                     const std::string& path, bool overwrite,
                     const JsonParameters& parameters = {});

// The same graph in DOT: minima blue, maxima red, saddles green; arcs labelled with their
// regular vertex count.
void write_reeb_dot(const reeb::ReebGraph& graph, const std::string& path, bool overwrite);

}  // namespace terrain::io
