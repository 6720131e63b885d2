#include "segment_job.hpp"

#include <cstdio>

#include "terrain/io/write_preview.hpp"

namespace terrain::cli {

void add_segment_options(po::options_description& options, SegmentOptionValues& values) {
    options.add_options()("persistence",
                          po::value(&values.simplify.persistence)->default_value(10.0),
                          "cancel arcs whose persistence is below P (field units)")(
        "area-ratio", po::value(&values.simplify.area_ratio)->default_value(0.5),
        "cancel arcs whose area ratio is below A percent of the surface")(
        "min-area", po::value(&values.min_area),
        "instead of --area-ratio: cancel arcs whose area on the body is below AREA (m^2, or "
        "5km2, 2000m2, 3ha), or auto: 20 pixels of the DEM (the default when no scale option "
        "is given)")(
        "cost", po::value(&values.cost)->default_value("auto"),
        "graph (Reeb-graph constrained), standard, or auto: graph for DEMs, standard for meshes")(
        "saddle-penalty", po::value(&values.grow.saddle_penalty)->default_value(20.0),
        "graph cost: penalty for joining a saddle with several unassigned branches")(
        "absorbed", po::value(&values.absorbed)->default_value("auto"),
        "divide: the vertices cancellations absorbed go back to the regions around them by "
        "their own values; whole: each surviving node grows as one unit (the paper); auto: "
        "divide for DEMs, whole for mesh files")(
        "format", po::value(&values.format)->default_value("GeoJSON"),
        "OGR driver of the region polygons (GeoJSON, GPKG, ...)")(
        "timings", po::bool_switch(&values.timings), "print the time of each stage");
}

void check_one_area_threshold(const po::variables_map& vm, const std::string& area_option) {
    if (vm.count(area_option) && vm.count("area-ratio") && !vm["area-ratio"].defaulted())
        throw UsageError("give --area-ratio or --" + area_option + ", not both");
}

pipeline::SegmentOptions to_pipeline_options(const FieldOptionValues& field,
                                             const SegmentOptionValues& values) {
    pipeline::SegmentOptions out;
    out.field = field.options.kind;
    out.shape_index = field.options.shape_index;
    out.rays = field.options.sdf.rays;
    out.cone_angle_degrees = field.cone_angle_degrees;
    out.postprocess = !field.no_postprocess;
    out.allow_open = field.options.sdf.allow_open;
    out.simplify = values.simplify;
    out.saddle_penalty = values.grow.saddle_penalty;
    out.format = values.format;
    out.landform_defaults = values.landform_defaults;
    if (values.craters != "on" && values.craters != "off")
        throw UsageError("--craters takes on or off, not '" + values.craters + "'");
    out.craters = values.craters == "on";
    // The numbers first, then the names (of several bad values, the first in this order is
    // the one reported).
    pipeline::check_options(out);
    out.cost = pipeline::parse_cost(values.cost);
    out.min_area = pipeline::parse_min_area(values.min_area);
    out.absorbed = pipeline::parse_absorbed(values.absorbed);
    return out;
}

void print_input_warnings(const char* command, const Input& input) {
    if (!input.dem) return;
    for (const auto& w : pipeline::georeference_warnings(*input.dem))
        std::fprintf(stderr, "terrain %s: warning: %s\n", command, w.c_str());
    if (const auto w = io::map_text_warning(); !w.empty())
        std::fprintf(stderr, "terrain %s: warning: %s\n", command, w.c_str());
}

void print_summary(const pipeline::SegmentResult& result, const std::string& output, bool timings) {
    std::printf(
        "%s: %u regions on %zu vertices (critical nodes %zu -> %zu)\n", output.c_str(),
        result.segmentation.region_count,
        result.mesh_counts ? result.mesh_counts->vertices : result.input.mesh.vertex_count(),
        result.critical_before, result.after.critical);
    if (timings) print_timings(result.timings);
}

void print_timings(const std::vector<pipeline::StageTime>& timings) {
    double total = 0;
    std::printf("%-10s %10s\n", "stage", "seconds");
    for (const auto& t : timings) {
        std::printf("%-10s %10.3f\n", t.name.c_str(), t.seconds);
        total += t.seconds;
    }
    std::printf("%-10s %10.3f\n", "total", total);
}

}  // namespace terrain::cli
