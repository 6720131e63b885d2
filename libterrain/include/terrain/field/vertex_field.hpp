#pragma once
// The scalar field the Reeb graph is built on, chosen by its kind, and its way back to the
// DEM's pixels.

#include <string>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/field/field_kind.hpp"
#include "terrain/field/sdf.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::field {

struct FieldOptions {
    FieldKind kind = FieldKind::shape_index;
    ShapeIndexOptions shape_index;
    SdfOptions sdf;
};

// Height above the reference body of each vertex: the DEM's height at the vertex's pixel
// (radius minus the semi-major axis for radius DEMs), or z for meshes read from files
// (dem == nullptr).
std::vector<float> height_field(const TriangleMesh& mesh, const Dem* dem);

// The field of `options.kind` on the mesh's vertices (shape_diameter_function for the SDF's
// counts and diameters).
std::vector<float> vertex_field(const TriangleMesh& mesh, const Dem* dem,
                                const FieldOptions& options, const ProgressFn& progress = {});

// Per-pixel values on the DEM's grid (row-major): each pixel takes its vertex's value, NaN
// where the DEM has NoData (or the pixel is in no triangle).
std::vector<float> field_to_pixels(const TriangleMesh& mesh, const Dem& dem,
                                   const std::vector<float>& field);

}  // namespace terrain::field
