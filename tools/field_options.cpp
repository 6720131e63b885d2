#include "field_options.hpp"

#include <numbers>

namespace terrain::cli {

void add_field_options(po::options_description& options, FieldOptionValues& values) {
    auto& si = values.options.shape_index;
    auto& sdf = values.options.sdf;
    options.add_options()("field", po::value(&values.name)->default_value("shape-index"),
                          "shape-index (x100, in [0,100]), sdf (Shape Diameter Function of a "
                          "closed mesh, in [0,100]) or height (metres above the reference)")(
        "rings", po::value(&si.rings)->default_value(2),
        "shape index: fit over the vertices within N mesh edges")(
        "radius", po::value(&si.radius)->default_value(0.0),
        "shape index: fit over the vertices within M metres instead of rings")(
        "rays", po::value(&sdf.rays)->default_value(25), "sdf: rays per face")(
        "cone-angle", po::value(&values.cone_angle_degrees)->default_value(120.0),
        "sdf: opening of each face's cone of rays, degrees")(
        "no-postprocess", po::bool_switch(&values.no_postprocess),
        "sdf: no bilateral smoothing of the face values")(
        "allow-open", po::bool_switch(&sdf.allow_open),
        "sdf: compute on a mesh with holes (rays through them are lost)");
}

field::FieldOptions to_field_options(const FieldOptionValues& values, const po::variables_map& vm) {
    field::FieldOptions out = values.options;
    out.kind = field::parse_field_kind(values.name);
    if (!vm["rings"].defaulted() && out.shape_index.radius > 0)
        throw UsageError("give --rings or --radius, not both");
    out.sdf.cone_angle = values.cone_angle_degrees * std::numbers::pi / 180.0;
    out.sdf.postprocess = !values.no_postprocess;
    return out;
}

}  // namespace terrain::cli
