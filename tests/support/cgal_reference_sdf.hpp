#pragma once
// The Shape Diameter Function as CGAL computes it, the reference field::shape_diameter_function
// is tested and benchmarked against (tests/field/sdf.cpp, tests/bench/bench_sdf.cpp). Kept out
// of the library so that only this file compiles CGAL's segmentation headers.

#include <vector>

#include "terrain/field/sdf.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::test {

// The face diameters (metres) `CGAL::sdf_values` gives on a CGAL Surface_mesh built from
// `mesh` (un-normalised with the range it returns when post-processing). Single-threaded and
// slow. Throws terrain::Error (stage "sdf") on bad options or when CGAL's halfedge structure
// cannot hold the mesh (non-manifold, repeated vertex in a face).
std::vector<double> cgal_sdf_face_diameters(const TriangleMesh& mesh,
                                            const field::SdfOptions& options = {});

}  // namespace terrain::test
