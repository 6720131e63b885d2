#include "support/cgal_reference_sdf.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/mesh_segmentation.h>

#include <numbers>
#include <string>

#include "terrain/core/error.hpp"

namespace terrain::test {

std::vector<double> cgal_sdf_face_diameters(const TriangleMesh& mesh,
                                            const field::SdfOptions& options) {
    // The options shape_diameter_function accepts.
    if (options.rays < 1) throw Error("sdf", "the number of rays must be at least 1");
    if (!(options.cone_angle > 0 && options.cone_angle < std::numbers::pi))
        throw Error("sdf", "the cone angle must be between 0 and 180 degrees (exclusive)");
    using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
    using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
    Mesh sm;
    sm.reserve(static_cast<Mesh::size_type>(mesh.vertex_count()), 0,
               static_cast<Mesh::size_type>(mesh.triangle_count()));
    for (const auto& p : mesh.positions) sm.add_vertex(Kernel::Point_3(p[0], p[1], p[2]));
    for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
        const auto& t = mesh.triangles[f];
        if (sm.add_face(Mesh::Vertex_index(t[0]), Mesh::Vertex_index(t[1]),
                        Mesh::Vertex_index(t[2])) == Mesh::null_face())
            throw Error("sdf", "CGAL's Surface_mesh cannot hold face " + std::to_string(f) +
                                   " (a repeated vertex or a non-manifold edge)");
    }
    auto sdf = sm.add_property_map<Mesh::Face_index, double>("f:sdf", 0.0).first;
    const auto [lo, hi] = CGAL::sdf_values(
        sm, sdf, options.cone_angle, static_cast<std::size_t>(options.rays), options.postprocess);
    std::vector<double> out(mesh.triangle_count());
    for (const auto f : sm.faces()) {
        const double v = sdf[f];
        // Post-processing normalises to [0,1] and returns the range it mapped (not when the
        // range is empty).
        out[f] = options.postprocess && hi > lo ? lo + v * (hi - lo) : v;
    }
    return out;
}

}  // namespace terrain::test
