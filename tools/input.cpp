#include "input.hpp"

#include "terrain/core/error.hpp"
#include "terrain/io/mesh_files.hpp"

namespace terrain::cli {
namespace {
// Peak bytes per DEM pixel of the mesh and the stages after it (field, Reeb graph,
// segmentation): about 160 measured for segment on a 1197x643 DEM; the SDF needs more.
constexpr double kPipelineBytesPerPixel = 200;
}  // namespace

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
                 const ProgressFn& progress) {
    pipeline::InputOptions options;
    options.dem = to_read_options(values.dem);  // checks the values, sets --max-memory
    options.dem.planned_bytes_per_pixel = kPipelineBytesPerPixel;
    options.repair = values.repair;
    if (!io::is_mesh_file(path)) {
        if (values.frame != "body" && values.frame != "map" && values.frame != "auto")
            throw Error("options", "--frame must be body, map or auto, not '" + values.frame + "'");
        options.frame = values.frame;
    }
    return pipeline::load_input(path, options, progress);
}

}  // namespace terrain::cli
