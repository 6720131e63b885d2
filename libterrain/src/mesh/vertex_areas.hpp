#pragma once
// Vertex areas, one third of each incident triangle's (vertex_areas.cpp).

#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::detail {

// Vertex areas: one third of each incident triangle (serial: the same sums every run).
void set_vertex_areas(TriangleMesh& mesh, const PassProgress& areas);

// The same sums for a DEM mesh, on every thread, by bands of block rows
// (add_in_order_by_bands): its triangles come in rows of blocks, a vertex of pixel row p a
// corner only in block rows p - 1 and p. False (nothing done) when a triangle is not so.
bool set_grid_vertex_areas(TriangleMesh& mesh, const ProgressFn& progress, double begin,
                           double end);

}  // namespace terrain::detail
