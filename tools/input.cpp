#include "input.hpp"

#include <chrono>

#include "terrain/core/error.hpp"
#include "terrain/io/mesh_files.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

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
    Input input;
    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    auto seconds = [](clock::time_point a, clock::time_point b) {
        return std::chrono::duration<double>(b - a).count();
    };
    if (io::is_mesh_file(path)) {
        to_read_options(values.dem);  // checks the values, sets --max-memory
        io::ReadMeshOptions read_options;
        read_options.repair = values.repair;
        input.mesh = io::read_mesh(path, read_options, progress);
        input.read_seconds = seconds(t0, clock::now());
        return input;
    }
    mesh::DemToMeshOptions mesh_options;
    if (values.frame == "body")
        mesh_options.frame = MeshFrame::body;
    else if (values.frame == "map")
        mesh_options.frame = MeshFrame::map;
    else if (values.frame != "auto")
        throw Error("options", "--frame must be body, map or auto, not '" + values.frame + "'");
    auto read_options = to_read_options(values.dem);
    read_options.planned_bytes_per_pixel = kPipelineBytesPerPixel;
    input.dem = io::read_dem(path, read_options, scaled_progress(progress, 0, 0.3));
    const auto t1 = clock::now();
    input.read_seconds = seconds(t0, t1);
    input.mesh = mesh::dem_to_mesh(*input.dem, mesh_options, scaled_progress(progress, 0.3, 1));
    input.mesh_seconds = seconds(t1, clock::now());
    return input;
}

}  // namespace terrain::cli
