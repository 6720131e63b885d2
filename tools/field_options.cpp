#include "field_options.hpp"

#include <cmath>
#include <numbers>

#include "terrain/core/error.hpp"

namespace terrain::cli {

void add_field_options(po::options_description& options, FieldOptionValues& values) {
    auto& si = values.options.shape_index;
    auto& sdf = values.options.sdf;
    options.add_options()("field", po::value(&values.name)->default_value("shape-index"),
                          "shape-index (x100, in [0,100]), sdf (Shape Diameter Function of a "
                          "closed mesh, in [0,100]) or height (metres above the reference)")(
        "rings", po::value(&si.rings)->default_value(2),
        "shape index: fit over the vertices within N mesh edges (1..10)")(
        "radius", po::value(&si.radius)->default_value(0.0),
        "shape index: fit over the vertices within M metres instead of rings (at most 20 "
        "mean edge lengths)")(
        "window", po::value(&values.window)->default_value("disk"),
        "shape index with --radius on a DEM: disk (the pixels within the radius on the ground; "
        "costs the same whatever the radius) or ball (the vertices within the radius in 3-D)")(
        "rays", po::value(&sdf.rays)->default_value(25), "sdf: rays per face (1..1000)")(
        "cone-angle", po::value(&values.cone_angle_degrees)->default_value(120.0),
        "sdf: opening of each face's cone of rays, degrees")(
        "no-postprocess", po::bool_switch(&values.no_postprocess),
        "sdf: no bilateral smoothing of the face values")(
        "allow-open", po::bool_switch(&sdf.allow_open),
        "sdf: compute on a mesh with holes (rays through them are lost)");
}

field::ShapeIndexWindow parse_window(const std::string& name) {
    if (name == "disk") return field::ShapeIndexWindow::disk;
    if (name == "ball") return field::ShapeIndexWindow::ball;
    throw Error("options", "--window must be disk or ball, not '" + name + "'");
}

field::FieldOptions to_field_options(const FieldOptionValues& values, const po::variables_map& vm) {
    field::FieldOptions out = values.options;
    out.kind = field::parse_field_kind(values.name);
    if (!vm["rings"].defaulted() && out.shape_index.radius > 0)
        throw UsageError("give --rings or --radius, not both");
    if (out.shape_index.rings < 1 || out.shape_index.rings > kMaxRings)
        throw Error("options", "--rings must be between 1 and " + std::to_string(kMaxRings));
    if (!(out.shape_index.radius >= 0) || !std::isfinite(out.shape_index.radius))
        throw Error("options", "--radius must be a positive number of metres");
    out.shape_index.window = parse_window(values.window);
    if (out.sdf.rays < 1 || out.sdf.rays > kMaxRays)
        throw Error("options", "--rays must be between 1 and " + std::to_string(kMaxRays));
    if (!(values.cone_angle_degrees > 0 && values.cone_angle_degrees < 180))
        throw Error("options", "--cone-angle must be between 0 and 180 degrees (exclusive)");
    out.sdf.cone_angle = values.cone_angle_degrees * std::numbers::pi / 180.0;
    out.sdf.postprocess = !values.no_postprocess;
    return out;
}

void check_field_limits(const field::FieldOptions& options, const TriangleMesh& mesh) {
    if (options.shape_index.radius <= 0 || mesh.triangles.empty()) return;
    double sum = 0;
    std::size_t edges = 0;
    for (const auto& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            const auto& a = mesh.positions[t[k]];
            const auto& b = mesh.positions[t[(k + 1) % 3]];
            sum += std::hypot(double(a[0]) - b[0], double(a[1]) - b[1], double(a[2]) - b[2]);
            ++edges;
        }
    const double mean = sum / double(edges);
    if (options.shape_index.radius > kMaxRadiusEdges * mean)
        throw Error("options", "--radius " + std::to_string(options.shape_index.radius) +
                                   " m is over " + std::to_string(int(kMaxRadiusEdges)) +
                                   " mean edge lengths (" + std::to_string(mean) +
                                   " m) of the mesh; use a smaller radius or --rings");
}

}  // namespace terrain::cli
