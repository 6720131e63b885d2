#include "terrain/pipeline/memory_plan.hpp"

#include "terrain/field/vertex_field.hpp"

namespace terrain::pipeline {

MemoryPlan memory_plan(const std::string& field, std::uint64_t limit) {
    MemoryPlan plan;
    plan.limit = limit;
    // Placeholder figures, replaced by the measured ones.
    plan.base_bytes = 64.0 * 1024 * 1024;
    plan.bytes_per_corner = 16;
    if (field.empty()) {  // reading and meshing
        plan.bytes_per_pixel = 100;
        plan.bytes_per_vertex = 200;
        plan.bytes_per_face = 300;
        return plan;
    }
    switch (field::parse_field_kind(field)) {
        case field::FieldKind::shape_index:
        case field::FieldKind::height:
            plan.bytes_per_pixel = 200;
            plan.bytes_per_vertex = 400;
            plan.bytes_per_face = 300;
            break;
        case field::FieldKind::sdf:
            plan.bytes_per_pixel = 400;
            plan.bytes_per_vertex = 400;
            plan.bytes_per_face = 600;
            break;
    }
    return plan;
}

}  // namespace terrain::pipeline
