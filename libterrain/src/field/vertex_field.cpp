#include "terrain/field/vertex_field.hpp"

#include <cmath>

#include "terrain/core/error.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

namespace terrain::field {

FieldKind parse_field_kind(const std::string& name) {
    if (const auto kind = value_named(kFieldKindNames, name)) return *kind;
    throw Error("field", "unknown field '" + name + "'; use shape-index, sdf or height");
}

const char* to_string(FieldKind kind) {
    return name_of(kFieldKindNames, kind);
}

std::vector<float> height_field(const TriangleMesh& mesh, const Dem* dem) {
    std::vector<float> out(mesh.vertex_count());
    for (std::size_t v = 0; v < out.size(); ++v) {
        if (dem && !mesh.vertex_pixel.empty()) {
            const auto p = static_cast<std::size_t>(mesh.vertex_pixel[v]);
            const double value = dem->values[p];
            out[v] = static_cast<float>(dem->elevation == ElevationKind::radius
                                            ? value - dem->body.semi_major_axis
                                            : value);
        } else {
            out[v] = static_cast<float>(mesh.position(v)[2]);
        }
    }
    return out;
}

std::vector<float> vertex_field(const TriangleMesh& mesh, const Dem* dem,
                                const FieldOptions& options, const ProgressFn& progress) {
    switch (options.kind) {
        case FieldKind::height: {
            auto out = height_field(mesh, dem);
            report_progress(progress, 1.0, "height");
            return out;
        }
        case FieldKind::sdf:
            return shape_diameter_function(mesh, options.sdf, progress).values;
        default:
            return shape_index_field(mesh, options.shape_index, progress);
    }
}

std::vector<float> field_to_pixels(const TriangleMesh& mesh, const Dem& dem,
                                   const std::vector<float>& field) {
    std::vector<std::int32_t> storage;
    const auto& p2v = mesh::pixel_vertices(mesh, dem, storage);
    std::vector<float> out(p2v.size(), std::nanf(""));
    for (std::size_t p = 0; p < p2v.size(); ++p)
        if (p2v[p] >= 0) out[p] = field[static_cast<std::size_t>(p2v[p])];
    return out;
}

}  // namespace terrain::field
