#pragma once
// The Shape Diameter Function as CGAL computes it, the reference field::shape_diameter_function
// is tested and benchmarked against (tests/field/sdf.cpp, tests/bench/bench_sdf.cpp). Kept out
// of the library, and off the library's mesh header, so that only this file compiles CGAL's
// segmentation headers and a change to TriangleMesh does not recompile it.

#include <array>
#include <cstdint>
#include <vector>

namespace terrain::test {

// The face diameters (metres) `CGAL::sdf_values` gives on a CGAL Surface_mesh built from the
// points and triangles (un-normalised with the range it returns when post-processing), with
// field::SdfOptions' rays, cone angle and post-processing. Single-threaded and slow. Throws
// terrain::Error (stage "sdf") on bad options or when CGAL's halfedge structure cannot hold
// the mesh (non-manifold, repeated vertex in a face).
std::vector<double> cgal_sdf_face_diameters(
    const std::vector<std::array<float, 3>>& positions,
    const std::vector<std::array<std::int32_t, 3>>& triangles, int rays, double cone_angle,
    bool postprocess);

// The same for a TriangleMesh and field::SdfOptions.
template <class Mesh, class SdfOptions>
std::vector<double> cgal_sdf_face_diameters(const Mesh& mesh, const SdfOptions& options) {
    return cgal_sdf_face_diameters(mesh.positions(), mesh.triangles(), options.rays,
                                   options.cone_angle, options.postprocess);
}

}  // namespace terrain::test
