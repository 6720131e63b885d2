// The segment job's options checked, and resolved on an input: the choices left to it (the
// cost, the absorbed vertices, the landform defaults), the area threshold, the field's and the
// simplification's options (terrain/pipeline/segment.hpp).
#include <cmath>
#include <numbers>

#include "terrain/core/error.hpp"
#include "terrain/pipeline/segment.hpp"

namespace terrain::pipeline {

void check_options(const SegmentOptions& o) {
    if (!std::isfinite(o.simplify.persistence) || o.simplify.persistence < 0)
        throw Error("segment", "--persistence must be a number >= 0");
    if (!std::isfinite(o.simplify.area_ratio) || o.simplify.area_ratio < 0 ||
        o.simplify.area_ratio > 100)
        throw Error("segment", "--area-ratio is a percentage of the surface: between 0 and 100");
    if (!std::isfinite(o.saddle_penalty) || o.saddle_penalty < 0)
        throw Error("segment", "--saddle-penalty must be a number >= 0");
    if (o.min_area.kind == MinArea::Kind::area &&
        (!std::isfinite(o.min_area.m2) || o.min_area.m2 <= 0))
        throw Error("segment",
                    "--min-area takes an area above 0 in m^2 or with a unit (5km2, 2000m2, 3ha); "
                    "'" +
                        to_string(o.min_area) + "' is not one");
}

SegmentOptions resolve_options(const SegmentOptions& options, bool dem) {
    SegmentOptions out = options;
    out.absorbed = absorbed_mode(options, dem);
    if (out.landform_defaults && dem && out.field == field::FieldKind::shape_index) {
        out.shape_index.auto_scale = true;
        out.min_area = MinArea::automatic();
    }
    out.landform_defaults = false;
    return out;
}

double min_area_m2(const SegmentOptions& options, const TriangleMesh& mesh) {
    if (!options.min_area.is_set()) return 0;
    if (!options.min_area.is_auto()) return options.min_area.m2;
    const double pixel = mean_vertex_area(mesh);
    if (!(pixel > 0) || !std::isfinite(pixel))
        throw Error("segment", "--min-area auto needs a mesh with a positive area");
    return kAutoMinAreaPixels * pixel;
}

reeb::SimplifyOptions simplify_options(const SegmentOptions& options, const TriangleMesh& mesh) {
    reeb::SimplifyOptions out = options.simplify;
    out.rewrite_field = false;  // (the regions grow on the graph and the field as computed)
    if (options.min_area.is_set())
        out.area_ratio = reeb::area_ratio_for_area(mesh, min_area_m2(options, mesh));
    return out;
}

field::FieldOptions field_options(const SegmentOptions& o) {
    field::FieldOptions out;
    out.kind = o.field;
    out.shape_index = o.shape_index;
    out.sdf.rays = o.rays;
    out.sdf.cone_angle = o.cone_angle_degrees * std::numbers::pi / 180.0;
    out.sdf.postprocess = o.postprocess;
    out.sdf.allow_open = o.allow_open;
    return out;
}

segment::GrowCost grow_cost(const SegmentOptions& o, bool dem) {
    return o.cost.value_or(dem ? segment::GrowCost::graph : segment::GrowCost::standard);
}

Absorbed absorbed_mode(const SegmentOptions& o, bool dem) {
    return o.absorbed.value_or(dem ? Absorbed::divide : Absorbed::whole);
}

}  // namespace terrain::pipeline
