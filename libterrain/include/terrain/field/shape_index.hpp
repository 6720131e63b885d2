#pragma once
// Koenderink's shape index on mesh vertices (Koenderink & van Doorn 1992), from principal
// curvatures of a quadric fitted in each vertex's tangent frame; mapped to [0,1] as Dorai &
// Jain (1997) do and scaled by 100, the units of the paper's thresholds (METHOD.md s.2).
// Sign convention fixed by behaviour: cap +1 (100), cup -1 (0), ridge +0.5 (75),
// valley -0.5 (25), saddle and plane 0 (50).

#include <vector>

#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::field {

// How the neighbourhood sums are made. mesh: per vertex over its gathered neighbours (cost
// grows with their number). grid (meshes made from a DEM, with a radius): from sums of the
// pixels' moments over tiles of the grid, summed-area tables for the disk window and row sums
// for the ball (docs/field.md). automatic: grid when it applies, else mesh.
enum class ShapeIndexMethod { automatic, mesh, grid };

// The window of a --radius neighbourhood on a mesh made from a DEM (meshes read from files
// always take the ball). disk: the pixels whose ground offset from the vertex, lifted onto its
// tangent plane, is within the radius (a disk on flat ground), drawn on the grid as six bands
// of rows, with a Monge fit over the horizontal plane; by the grid method its sums come from
// summed-area tables at a cost that does not grow with the radius. ball: the vertices within
// the radius in 3-D, reached through vertices within it, with the tangent-frame fit
// (docs/field.md, "Windows and methods").
enum class ShapeIndexWindow { disk, ball };

struct ShapeIndexOptions {
    int rings = 2;      // neighbourhood: vertices within this many mesh edges
    double radius = 0;  // > 0: vertices within this distance in metres instead of rings
    // Curvedness times the mean neighbour distance below this is a planar point (SI 0).
    double planar_curvedness = 1e-4;
    ShapeIndexMethod method = ShapeIndexMethod::automatic;
    ShapeIndexWindow window = ShapeIndexWindow::disk;
};

// The method shape_index_field takes for this mesh and these options: "grid" or "mesh".
// Throws terrain::Error when `grid` is asked for a mesh not made from a DEM.
const char* shape_index_method(const TriangleMesh& mesh, const ShapeIndexOptions& options);

// The neighbourhood shape_index_field takes: "rings", "disk" or "ball".
const char* shape_index_window(const TriangleMesh& mesh, const ShapeIndexOptions& options);

struct PrincipalCurvatures {
    double k1 = 0, k2 = 0;  // k1 >= k2, positive where the surface is convex (a cap)
};

// Shape index in [-1, 1] of principal curvatures (k1 >= k2, convex positive); 0 when both
// vanish.
double shape_index(double k1, double k2);

// Per-vertex principal curvatures (convex positive, normals outwards/up).
std::vector<PrincipalCurvatures> principal_curvatures(const TriangleMesh& mesh,
                                                      const ShapeIndexOptions& options = {},
                                                      const ProgressFn& progress = {});

// Per-vertex shape index mapped to [0, 100]: 50 * (SI + 1). Multi-threaded, deterministic.
std::vector<float> shape_index_field(const TriangleMesh& mesh,
                                     const ShapeIndexOptions& options = {},
                                     const ProgressFn& progress = {});

}  // namespace terrain::field
