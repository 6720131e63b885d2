#include "support/cgal_reference_sdf.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/mesh_segmentation.h>

#include <numbers>
#include <string>

#include "terrain/core/error.hpp"

namespace terrain::test {

std::vector<double> cgal_sdf_face_diameters(
    const std::vector<std::array<float, 3>>& positions,
    const std::vector<std::array<std::int32_t, 3>>& triangles, int rays, double cone_angle,
    bool postprocess) {
    // The options shape_diameter_function accepts.
    if (rays < 1) throw Error("sdf", "the number of rays must be at least 1");
    if (!(cone_angle > 0 && cone_angle < std::numbers::pi))
        throw Error("sdf", "the cone angle must be between 0 and 180 degrees (exclusive)");
    using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
    using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
    Mesh sm;
    sm.reserve(static_cast<Mesh::size_type>(positions.size()), 0,
               static_cast<Mesh::size_type>(triangles.size()));
    for (const auto& p : positions) sm.add_vertex(Kernel::Point_3(p[0], p[1], p[2]));
    for (std::size_t f = 0; f < triangles.size(); ++f) {
        const auto& t = triangles[f];
        if (sm.add_face(Mesh::Vertex_index(t[0]), Mesh::Vertex_index(t[1]),
                        Mesh::Vertex_index(t[2])) == Mesh::null_face())
            throw Error("sdf", "CGAL's Surface_mesh cannot hold face " + std::to_string(f) +
                                   " (a repeated vertex or a non-manifold edge)");
    }
    auto sdf = sm.add_property_map<Mesh::Face_index, double>("f:sdf", 0.0).first;
    const auto [lo, hi] =
        CGAL::sdf_values(sm, sdf, cone_angle, static_cast<std::size_t>(rays), postprocess);
    std::vector<double> out(triangles.size());
    for (const auto f : sm.faces()) {
        const double v = sdf[f];
        // Post-processing normalises to [0,1] and returns the range it mapped (not when the
        // range is empty).
        out[f] = postprocess && hi > lo ? lo + v * (hi - lo) : v;
    }
    return out;
}

}  // namespace terrain::test
