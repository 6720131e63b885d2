#pragma once
// The Shape Diameter Function of a closed mesh (Shapira, Shamir & Cohen-Or 2008, "Consistent
// mesh partitioning and skeletonisation using the shape diameter function"), as CGAL's
// Surface_mesh_segmentation computes it (`CGAL::sdf_values` with its post-processing), with
// our own multi-threaded ray caster; per vertex, normalised to [0,1] and scaled by 100
// (METHOD.md s.2). docs/field.md says what is computed and how it compares with CGAL.

#include <cstddef>
#include <numbers>
#include <vector>

#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::field {

// CGAL's defaults (mesh_segmentation.h).
struct SdfOptions {
    int rays = 25;                                     // rays per face
    double cone_angle = 2.0 / 3.0 * std::numbers::pi;  // opening of the cone, radians, (0, pi)
    // Fill faces with no value from their neighbours and smooth with CGAL's bilateral filter.
    // Without it faces with no value are still filled (a field has no holes), never smoothed.
    bool postprocess = true;
    // The SDF needs a closed mesh: an open one (boundary or non-manifold edges) is refused
    // unless this is set; then rays leaving through the holes are simply lost.
    bool allow_open = false;
};

struct SdfResult {
    std::vector<float> values;            // per vertex, in [0, 100]
    std::vector<double> face_diameters;   // per face, metres (after post-processing)
    double min_diameter = 0;              // the vertex diameters mapped to 0 and 100: the
    double max_diameter = 0;              // area-weighted means of the incident faces'
    std::size_t degenerate_faces = 0;     // zero-area faces: no rays, value from neighbours
    std::size_t faces_without_value = 0;  // faces none of whose rays met the inner surface
    std::size_t boundary_edges = 0;       // edges in one face (allow_open)
    std::size_t nonmanifold_edges = 0;    // edges in more than two faces (allow_open)
    bool reoriented = false;              // faces were oriented inwards: rays cast the other way
};

// The SDF of every vertex (values) and face. Throws terrain::Error (stage "sdf") for an open
// mesh (unless allow_open), bad options or a mesh without a usable face. Multi-threaded;
// the same result for any thread count.
SdfResult shape_diameter_function(const TriangleMesh& mesh, const SdfOptions& options = {},
                                  const ProgressFn& progress = {});

}  // namespace terrain::field
