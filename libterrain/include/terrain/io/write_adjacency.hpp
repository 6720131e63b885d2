#pragma once
// The region adjacency graph as files, three ways (docs/outputs.md). Like every writer of io/:
// atomic, refuses an existing file unless `overwrite`, throws one terrain::Error (stage
// "write") on failure, and writes the same bytes for the same input.

#include <string>

#include "terrain/segment/regions.hpp"

namespace terrain::io {

// adjacency.json: {"directed": false, "multigraph": false, "graph": {...}, "nodes": [...],
// "edges": [...]} (networkx: node_link_graph(data, edges="edges")).
void write_adjacency_json(const segment::RegionGraph& graph, const std::string& path,
                          bool overwrite);
// adjacency.graphml: the same graph with typed keys (networkx read_graphml, Gephi).
void write_adjacency_graphml(const segment::RegionGraph& graph, const std::string& path,
                             bool overwrite);
// adjacency.geojson: a Point per region at its representative vertex and a LineString per
// edge between the two points, in the graph's point frame.
void write_adjacency_geojson(const segment::RegionGraph& graph, const std::string& path,
                             bool overwrite);

}  // namespace terrain::io
