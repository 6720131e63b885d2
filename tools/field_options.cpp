#include "field_options.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "terrain/core/error.hpp"
#include "terrain/pipeline/options.hpp"

namespace terrain::cli {

void add_field_options(po::options_description& options, FieldOptionValues& values) {
    auto& si = values.options.shape_index;
    auto& sdf = values.options.sdf;
    options.add_options()("field", po::value(&values.name)->default_value("shape-index"),
                          "shape-index (x100, in [0,100]), sdf (Shape Diameter Function of a "
                          "closed mesh, in [0,100]) or height (metres above the reference)")(
        "rings", po::value(&si.rings)->default_value(2),
        "shape index: fit over the vertices within N mesh edges (1..10)")(
        "radius", po::value(&values.radius),
        "shape index: fit over the vertices within M metres instead of rings (the disk window "
        "at most 128 pixels, the ball at most 20 mean edge lengths), or auto: the radius chosen "
        "per vertex among --radii "
        "(DEMs; the default when no scale option is given)")(
        "radii", po::value(&values.radii),
        "with --radius auto: the ladder of radii in metres, R1,R2,... increasing (default: 2, "
        "4, 8, ..., 128 pixels, below half the grid's smaller side and half the body's "
        "radius)")(
        "window", po::value(&values.window)->default_value("disk"),
        "shape index with --radius on a DEM: disk (the pixels within the radius on the ground; "
        "costs the same at any radius up to 128 pixels) or ball (the vertices within the radius in "
        "3-D)")("rays", po::value(&sdf.rays)->default_value(25), "sdf: rays per face (1..1000)")(
        "cone-angle", po::value(&values.cone_angle_degrees)->default_value(120.0),
        "sdf: opening of each face's cone of rays, degrees")(
        "no-postprocess", po::bool_switch(&values.no_postprocess),
        "sdf: no bilateral smoothing of the face values")(
        "allow-open", po::bool_switch(&sdf.allow_open),
        "sdf: compute on a mesh with holes (rays through them are lost)");
}

bool no_scale_option(const po::variables_map& vm) {
    for (const char* name : {"rings", "radius", "radii", "persistence", "area-ratio", "min-area",
                             "area-ratios", "min-areas"})
        if (vm.count(name) && !vm[name].defaulted()) return false;
    return true;
}

namespace {

std::vector<double> parse_radii(const std::string& text) {
    std::vector<double> out;
    std::size_t start = 0;
    while (start <= text.size()) {
        const auto end = std::min(text.find(',', start), text.size());
        const std::string item = text.substr(start, end - start);
        std::size_t used = 0;
        double value = 0;
        try {
            value = std::stod(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != item.size() || !(value > 0) || !std::isfinite(value))
            throw Error("options", "--radii takes metres above 0 separated by commas; '" + item +
                                       "' is not one");
        out.push_back(value);
        start = end + 1;
    }
    return out;
}

}  // namespace

field::FieldOptions to_field_options(const FieldOptionValues& values, const po::variables_map& vm) {
    field::FieldOptions out = values.options;
    out.kind = field::parse_field_kind(values.name);
    if (values.radius == "auto") {
        out.shape_index.auto_scale = true;
    } else if (!values.radius.empty()) {
        std::size_t used = 0;
        try {
            out.shape_index.radius = std::stod(values.radius, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != values.radius.size())
            throw Error("options",
                        "--radius takes metres or auto; '" + values.radius + "' is neither");
    }
    if (!values.radii.empty()) {
        if (!out.shape_index.auto_scale) throw UsageError("--radii goes with --radius auto");
        out.shape_index.radii = parse_radii(values.radii);
    }
    if (!vm["rings"].defaulted() && (out.shape_index.radius > 0 || out.shape_index.auto_scale))
        throw UsageError("give --rings or --radius, not both");
    if (out.shape_index.rings < 1 || out.shape_index.rings > kMaxRings)
        throw Error("options", "--rings must be between 1 and " + std::to_string(kMaxRings));
    if (!(out.shape_index.radius >= 0) || !std::isfinite(out.shape_index.radius))
        throw Error("options", "--radius must be a positive number of metres");
    out.shape_index.window = pipeline::parse_window(values.window);
    if (out.sdf.rays < 1 || out.sdf.rays > kMaxRays)
        throw Error("options", "--rays must be between 1 and " + std::to_string(kMaxRays));
    if (!(values.cone_angle_degrees > 0 && values.cone_angle_degrees < 180))
        throw Error("options", "--cone-angle must be between 0 and 180 degrees (exclusive)");
    out.sdf.cone_angle = values.cone_angle_degrees * std::numbers::pi / 180.0;
    out.sdf.postprocess = !values.no_postprocess;
    return out;
}

void check_field_limits(const field::FieldOptions& options, const TriangleMesh& mesh) {
    if (options.kind != field::FieldKind::shape_index || options.shape_index.auto_scale ||
        options.shape_index.radius <= 0)
        return;
    if (std::string(field::shape_index_window(mesh, options.shape_index)) == "disk") {
        // Any radius the tables hold costs the same (the field refuses one reaching further:
        // field::detail::check_window_reach); one wider than the grid sees nothing more.
        const double spacing = std::sqrt(mean_vertex_area(mesh));
        const double across = double(std::max(mesh.grid_width, mesh.grid_height)) * spacing;
        if (options.shape_index.radius > across)
            throw Error("options", "--radius " + std::to_string(options.shape_index.radius) +
                                       " m is wider than the grid (" + std::to_string(across) +
                                       " m across); use a smaller radius");
        return;
    }
    // The mean length of the mesh's edges, each counted from both ends.
    double sum = 0;
    std::size_t edges = 0;
    for (std::size_t v = 0; v < mesh.vertex_count() && v < mesh.positions().size(); ++v)
        for (const auto w : mesh.neighbors_of(v)) {
            const auto& a = mesh.positions()[v];
            const auto& b = mesh.positions()[std::size_t(w)];
            sum += std::hypot(double(a[0]) - b[0], double(a[1]) - b[1], double(a[2]) - b[2]);
            ++edges;
        }
    if (edges == 0) return;
    const double mean = sum / double(edges);
    if (options.shape_index.radius > kMaxRadiusEdges * mean)
        throw Error("options", "--radius " + std::to_string(options.shape_index.radius) +
                                   " m is over " + std::to_string(int(kMaxRadiusEdges)) +
                                   " mean edge lengths (" + std::to_string(mean) +
                                   " m) of the mesh; use a smaller radius or --rings");
}

}  // namespace terrain::cli
