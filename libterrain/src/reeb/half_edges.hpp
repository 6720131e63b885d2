#pragma once
// Private: half-edges of a consistently oriented triangle mesh, for the contour-tracking
// sweep (contour_sweep.cpp), which walks contours from triangle to triangle across edges and
// turns around a vertex through the triangles of its star.

#include <vector>

#include "terrain/internal/core/indices.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::reeb::internal {

using detail::i32;

// Half-edge h = 3*t + k runs from corner k of triangle t to corner (k+1)%3.
inline i32 next_he(i32 h) {
    return h % 3 == 2 ? h - 2 : h + 1;
}
inline i32 prev_he(i32 h) {
    return h % 3 == 0 ? h + 2 : h - 1;
}

struct HalfEdges {
    std::vector<i32> twin;        // opposite half-edge, kNone on the boundary
    std::vector<i32> vertex_out;  // a half-edge leaving each vertex; on the boundary, the one
                                  // with no twin, so that rotating covers the whole fan
};

// Throws terrain::Error when an edge is used twice in the same direction (a non-manifold or
// inconsistently oriented mesh) or the adjacency does not match the triangles.
HalfEdges build_half_edges(const TriangleMesh& mesh);

}  // namespace terrain::reeb::internal
