// terrain reeb INPUT [field options] [--persistence P] [--area-ratio A | --min-area AREA]
//                    -o GRAPH.json|.dot
//                    [--write-field OUT]: the (simplified) Reeb graph of the field.
#include <cstdio>
#include <filesystem>

#include "cli.hpp"
#include "field_options.hpp"
#include "input.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/io/mesh_files.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/write_raster.hpp"
#include "terrain/io/write_reeb_graph.hpp"
#include "terrain/pipeline/segment.hpp"
#include "terrain/reeb/simplify.hpp"

namespace terrain::cli {
namespace {
bool same_file(const std::string& a, const std::string& b) {
    std::error_code ec;
    return std::filesystem::weakly_canonical(std::filesystem::absolute(a), ec) ==
           std::filesystem::weakly_canonical(std::filesystem::absolute(b), ec);
}
}  // namespace

int run_reeb(int argc, char** argv) {
    return guarded("reeb", [&] {
        CommonValues common;
        std::string field_output, algorithm = "auto", min_area;
        InputOptionValues input_values;
        FieldOptionValues field_values;
        reeb::SimplifyOptions simplify_options;
        po::options_description options("terrain reeb options");
        add_common_options(options, common, "GRAPH.json (or GRAPH.dot for GraphViz)");
        options.add_options()("persistence",
                              po::value(&simplify_options.persistence)->default_value(0.0),
                              "cancel arcs whose persistence is below P (field units)")(
            "area-ratio", po::value(&simplify_options.area_ratio)->default_value(0.0),
            "cancel arcs whose area ratio is below A percent of the surface")(
            "min-area", po::value(&min_area),
            "instead of --area-ratio: cancel arcs whose area on the body is below AREA (m^2, or "
            "5km2, 2000m2, 3ha)")("write-field", po::value(&field_output),
                                  "also write the simplified field (OUT.tif for a DEM, OUT.ply)")(
            "algorithm", po::value(&algorithm)->default_value("auto"),
            "auto, sweep or contour-tree (disks and spheres only)");
        add_field_options(options, field_values);
        add_input_options(options, input_values);
        po::variables_map vm;
        if (!parse_command(argc, argv,
                           "terrain reeb INPUT [--field F] [--persistence P] [--area-ratio A | "
                           "--min-area AREA] -o "
                           "GRAPH.json [--write-field OUT]",
                           options, vm))
            return 0;
        const auto field_options = to_field_options(field_values, vm);
        if (vm.count("min-area") && !vm["area-ratio"].defaulted())
            throw UsageError("give --area-ratio or --min-area, not both");
        const double min_area_m2 = min_area.empty() ? 0.0 : pipeline::parse_area(min_area);
        reeb::ReebOptions reeb_options;
        if (algorithm == "sweep")
            reeb_options.algorithm = reeb::ReebAlgorithm::sweep;
        else if (algorithm == "contour-tree")
            reeb_options.algorithm = reeb::ReebAlgorithm::contour_tree;
        else if (algorithm != "auto")
            throw Error("options",
                        "--algorithm must be auto, sweep or contour-tree, not '" + algorithm + "'");
        const std::string ext = std::filesystem::path(common.output).extension().string();
        if (ext != ".json" && ext != ".dot")
            throw UsageError("the output must end in .json or .dot");
        io::check_output_path(common.output, common.overwrite);
        if (!field_output.empty()) io::check_output_path(field_output, common.overwrite);
        if (!field_output.empty() && same_file(field_output, common.output))
            throw UsageError("--write-field and -o name the same file '" + common.output + "'");

        const auto progress = terminal_progress(common.quiet);
        const Input input = load_input(common.input, input_values, field_options.kind,
                                       scaled_progress(progress, 0, 0.3));
        const Dem* dem = input.dem ? &*input.dem : nullptr;
        if (!min_area.empty())
            simplify_options.area_ratio = reeb::area_ratio_for_area(input.mesh, min_area_m2);
        reeb::check_simplify_options(simplify_options);  // before the long steps
        check_field_limits(field_options, input.mesh);
        const auto values = field::vertex_field(input.mesh, dem, field_options,
                                                scaled_progress(progress, 0.3, 0.7));
        auto graph = reeb::build_reeb_graph(input.mesh, values, reeb_options,
                                            scaled_progress(progress, 0.7, 0.85));
        const auto before = reeb::summarize(graph);
        std::vector<float> simplified = values;
        if (simplify_options.persistence > 0 || simplify_options.area_ratio > 0) {
            auto result = reeb::simplify(input.mesh, graph, simplify_options,
                                         scaled_progress(progress, 0.85, 0.95));
            graph = std::move(result.graph);
            simplified = std::move(result.field);
        }
        if (ext == ".dot") {
            io::write_reeb_dot(graph, common.output, common.overwrite);
        } else {
            std::vector<std::pair<std::string, std::string>> extra = {
                {"input", JsonWriter::escape(common.input)},
                {"field", JsonWriter::escape(field_values.name)},
                {"persistence", JsonWriter::number(simplify_options.persistence)},
                {"area_ratio_percent", JsonWriter::number(simplify_options.area_ratio)}};
            if (!min_area.empty()) {
                extra.emplace_back("min_area", JsonWriter::escape(min_area));
                extra.emplace_back("min_area_m2", JsonWriter::number(min_area_m2));
            }
            extra.emplace_back("critical_nodes_before_simplification",
                               std::to_string(before.critical));
            io::write_reeb_json(graph, input.mesh, common.output, common.overwrite, extra);
        }
        if (!field_output.empty()) {
            if (io::is_mesh_file(field_output)) {
                io::write_ply(input.mesh, field_output, common.overwrite, {{"field", &simplified}});
            } else {
                if (!dem) throw UsageError("a mesh input gives a .ply field, not a raster");
                io::write_float_raster(*dem, field::field_to_pixels(input.mesh, *dem, simplified),
                                       field_output, common.overwrite,
                                       "simplified " + field_values.name);
            }
        }
        report_progress(progress, 1.0);
        const auto s = reeb::summarize(graph);
        std::printf(
            "%s: %zu critical nodes (%zu minima, %zu maxima, %zu saddles), %zu arcs, %zu loops; "
            "%zu critical nodes before simplification\n",
            common.output.c_str(), s.critical, s.minima, s.maxima, s.saddles, s.arcs, s.loops,
            before.critical);
        return 0;
    });
}

}  // namespace terrain::cli
