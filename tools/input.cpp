#include "input.hpp"

#include "terrain/core/error.hpp"
#include "terrain/core/memory_budget.hpp"
#include "terrain/io/mesh_files.hpp"

namespace terrain::cli {

void add_input_options(po::options_description& options, InputOptionValues& values) {
    add_dem_options(options, values.dem);
    options.add_options()(
        "frame", po::value(&values.frame)->default_value("auto"),
        "body|map|auto: body-fixed X,Y,Z on the body, or map easting/northing/height "
        "(auto: body for planetary and geographic CRSs, map otherwise)")(
        "repair", po::bool_switch(&values.repair),
        "mesh input: repair degenerate or non-manifold elements instead of refusing");
}

Input load_input(const std::string& path, const InputOptionValues& values,
                 std::optional<field::FieldKind> field, const ProgressFn& progress, bool segment) {
    pipeline::InputOptions options;
    options.dem = to_read_options(values.dem);  // checks the values
    // The pipeline's memory plan for the field computed next (segment: pipeline::segment's),
    // with --max-memory.
    options.planned_field = field;
    options.planned_segment = segment;
    if (!values.dem.max_memory.empty())
        options.max_memory = parse_memory_size(values.dem.max_memory);
    options.repair = values.repair;
    // (A mesh file keeps its own frame: --frame is not read.)
    if (!io::is_mesh_file(path) && values.frame != "auto") {
        options.frame = value_named(pipeline::kFrameNames, values.frame);
        if (!options.frame)
            throw Error("options", "--frame must be body, map or auto, not '" + values.frame + "'");
    }
    return pipeline::load_input(path, options, progress);
}

}  // namespace terrain::cli
