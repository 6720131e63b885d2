#include "field_options.hpp"

namespace terrain::cli {

void add_field_options(po::options_description& options, FieldOptionValues& values) {
    auto& si = values.options.shape_index;
    options.add_options()("field", po::value(&values.name)->default_value("shape-index"),
                          "shape-index (x100, in [0,100]) or height (metres above the reference)")(
        "rings", po::value(&si.rings)->default_value(2),
        "shape index: fit over the vertices within N mesh edges")(
        "radius", po::value(&si.radius)->default_value(0.0),
        "shape index: fit over the vertices within M metres instead of rings");
}

field::FieldOptions to_field_options(const FieldOptionValues& values, const po::variables_map& vm) {
    field::FieldOptions out = values.options;
    if (values.name == "sdf")
        throw UsageError("--field sdf is not available yet; use shape-index or height");
    out.kind = field::parse_field_kind(values.name);
    if (!vm["rings"].defaulted() && out.shape_index.radius > 0)
        throw UsageError("give --rings or --radius, not both");
    return out;
}

}  // namespace terrain::cli
