#pragma once
// Private: the contour tree, the Reeb graph of a field on a mesh without loops.

#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"

namespace terrain::reeb::internal {

// True when the Reeb graph of any field on the mesh is a tree: every connected component is
// of genus 0 with at most one boundary loop (a disk or a sphere). Assumes a 2-manifold.
// A DEM mesh in which every pixel has its vertex is one component, read from its counts
// (one report, at the end); other meshes go through loop_free_by_components.
bool loop_free(const TriangleMesh& mesh, const ProgressFn& progress = {});
// The same from the components a union-find over the triangles finds, each one's Euler
// characteristic counted over its vertices and triangles. Reports its passes (triangles,
// vertices, triangles) through `progress`, 0 to 1.
bool loop_free_by_components(const TriangleMesh& mesh, const ProgressFn& progress = {});

// The Reeb graph of the field whose events order_events put in g, when the mesh has no loops
// (then it is the contour tree). Returns false, leaving the graph half made, when the mesh
// has handles or holes. Enters Stage::reeb_links (which reads no field), Stage::reeb_sweeps, with
// g's vertex lists, offsets, vertices' nodes and node values stashed (the sweeps do not read them),
// then Stage::reeb_arcs.
bool contour_tree(const TriangleMesh& mesh, ReebGraph& g, const ProgressFn& progress,
                  Residency& memory = all_resident());

}  // namespace terrain::reeb::internal
