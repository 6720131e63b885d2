// terrain sweep INPUT -o OUTDIR --area-ratios 0.1,0.25,0.5,1,2 [segment options]
// One segmentation per area ratio, reusing the field and the unsimplified Reeb graph; the
// scales run side by side on the cores. Outputs: labels.tif (one band per scale),
// regions.gpkg (one layer per scale) and regions_<ratio>.geojson, adjacency_<ratio>.json,
// lineage.json (how each region overlaps the regions of the next scale), sweep.csv,
// sweep.png and run.json. See docs/sweep.md.
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "cli.hpp"
#include "field_options.hpp"
#include "input.hpp"
#include "segment_job.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/io/write_adjacency.hpp"
#include "terrain/io/write_label_stack.hpp"
#include "terrain/io/write_mesh_labels.hpp"
#include "terrain/io/write_region_polygons.hpp"
#include "terrain/io/write_sweep_plot.hpp"
#include "terrain/segment/lineage.hpp"

namespace terrain::cli {

namespace {

std::vector<double> parse_ratios(const std::string& text) {
    std::vector<double> out;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        std::size_t used = 0;
        double v = 0;
        try {
            v = std::stod(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used != item.size() || !std::isfinite(v) || v <= 0 || v > 100)
            throw Error("sweep",
                        "--area-ratios takes percentages in (0, 100] separated by commas; '" +
                            item + "' is not one");
        out.push_back(v);
    }
    if (out.empty()) throw Error("sweep", "--area-ratios needs at least one value");
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

struct Scale {
    double ratio = 0;
    std::string name;  // the ratio as written in file names ("0.25")
    segment::Segmentation segmentation;
    reeb::ReebSummary after;  // of its simplified graph
    segment::RegionGraph regions;
    double seconds = 0;
};

void write_text(const std::string& path, const std::string& text) {
    std::ofstream f(path, std::ios::binary);
    f << text;
    f.flush();
    if (!f) throw Error("write", "cannot write " + path);
}

}  // namespace

int run_sweep(int argc, char** argv) {
    return guarded("sweep", [&] {
        CommonValues common;
        std::string ratios_text;
        InputOptionValues input_values;
        FieldOptionValues field_values;
        SegmentOptionValues segment_values;
        po::options_description options("terrain sweep options");
        add_common_options(options, common, "OUTDIR: the directory to write");
        options.add_options()("area-ratios",
                              po::value(&ratios_text)->default_value("0.1,0.25,0.5,1,2"),
                              "the scales: area-ratio thresholds in percent, comma separated");
        add_segment_options(options, segment_values);
        add_field_options(options, field_values);
        add_input_options(options, input_values);
        po::variables_map vm;
        if (!parse_command(
                argc, argv,
                "terrain sweep INPUT -o OUTDIR --area-ratios 0.1,0.25,0.5,1,2 [segment options]",
                options, vm))
            return 0;
        if (!vm["area-ratio"].defaulted())
            throw UsageError("terrain sweep takes --area-ratios (a list), not --area-ratio");
        const auto field_options = to_field_options(field_values, vm);
        check_segment_options(segment_values);
        const auto ratios = parse_ratios(ratios_text);
        OutputDirectory dir(common.output, common.overwrite);
        const std::string d = dir.temp_path() + "/";

        const auto progress = terminal_progress(common.quiet);
        SegmentJob job;
        job.input = load_input(common.input, input_values, scaled_progress(progress, 0, 0.15));
        job.add_time("read", job.input.read_seconds);
        if (job.input.dem) job.add_time("mesh", job.input.mesh_seconds);
        compute_field(job, field_options, scaled_progress(progress, 0.15, 0.4));
        compute_reeb(job, scaled_progress(progress, 0.4, 0.5));

        // Every scale from the same unsimplified graph, as `segment` would do it.
        std::vector<Scale> scales(ratios.size());
        const auto t0 = std::chrono::steady_clock::now();
        tbb::parallel_for(std::size_t{0}, scales.size(), [&](std::size_t i) {
            const auto s0 = std::chrono::steady_clock::now();
            SegmentOptionValues values = segment_values;
            values.simplify.area_ratio = ratios[i];
            auto result = segment_scale(job, values);
            scales[i].ratio = ratios[i];
            scales[i].name = JsonWriter::number(ratios[i]);
            scales[i].after = result.after;
            scales[i].segmentation = std::move(result.segmentation);
            scales[i].regions =
                segment::region_graph(job.input.mesh, job.field, scales[i].segmentation.labels,
                                      scales[i].segmentation.region_count, job.dem());
            scales[i].seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
        });
        job.add_time("scales",
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        report_progress(progress, 0.75);

        // Outputs.
        const auto w0 = std::chrono::steady_clock::now();
        std::vector<std::string> files;
        const Dem* dem = job.dem();
        if (dem) {
            std::vector<std::vector<std::uint32_t>> bands;
            std::vector<std::string> descriptions;
            for (const auto& s : scales) {
                bands.push_back(segment::label_pixels(job.input.mesh, *dem, s.segmentation.labels));
                descriptions.push_back("area_ratio=" + s.name);
            }
            io::write_label_stack(*dem, bands, descriptions, d + "labels.tif", false);
            files.push_back("labels.tif");
            // Each scale polygonized once; then the GeoPackage's layers one after the other,
            // the GeoJSON files beside them.
            std::vector<io::RegionPolygons> polygons(scales.size());
            tbb::parallel_for(std::size_t{0}, scales.size(), [&](std::size_t i) {
                polygons[i] =
                    io::polygonize_regions(*dem, bands[i], scales[i].regions.regions.size());
            });
            tbb::parallel_invoke(
                [&] {
                    for (std::size_t i = 0; i < scales.size(); ++i) {
                        io::RegionPolygonOptions gpkg;
                        gpkg.driver = "GPKG";
                        gpkg.layer = "regions_" + scales[i].name;
                        gpkg.append_layer = true;
                        io::write_region_polygons(*dem, polygons[i], scales[i].regions,
                                                  d + "regions.gpkg", false, gpkg);
                    }
                },
                [&] {
                    tbb::parallel_for(std::size_t{0}, scales.size(), [&](std::size_t i) {
                        io::write_region_polygons(*dem, polygons[i], scales[i].regions,
                                                  d + "regions_" + scales[i].name + ".geojson",
                                                  false);
                    });
                });
            files.push_back("regions.gpkg");
            for (const auto& s : scales) files.push_back("regions_" + s.name + ".geojson");
        } else {
            for (const auto& s : scales) {
                io::write_faces_seg(job.input.mesh, s.segmentation.labels,
                                    d + "faces_" + s.name + ".seg", false);
                files.push_back("faces_" + s.name + ".seg");
            }
        }
        for (const auto& s : scales) {
            io::write_adjacency_json(s.regions, d + "adjacency_" + s.name + ".json", false);
            files.push_back("adjacency_" + s.name + ".json");
        }
        // lineage.json: scale i -> scale i+1.
        {
            std::ofstream os(d + "lineage.json", std::ios::binary);
            JsonWriter j(os);
            j.begin_object();
            j.key("scales").begin_array();
            for (const auto& s : scales) j.value(s.ratio);
            j.end_array();
            j.field("area_unit",
                    dem ? "m^2 of pixel footprints on the body" : "m^2 of mesh surface");
            j.key("links").begin_array();
            for (std::size_t i = 0; i + 1 < scales.size(); ++i) {
                const auto& a = scales[i];
                const auto& b = scales[i + 1];
                const auto lin = segment::region_lineage(
                    job.input.mesh, dem, a.segmentation.labels, a.segmentation.region_count,
                    b.segmentation.labels, b.segmentation.region_count);
                j.begin_object().field("from_area_ratio", a.ratio).field("to_area_ratio", b.ratio);
                j.key("regions").begin_array();
                for (const auto& r : lin) {
                    j.begin_object()
                        .field("region", static_cast<std::int64_t>(r.region))
                        .field("area_m2", r.area_m2);
                    j.key("overlaps").begin_array();
                    for (const auto& o : r.overlaps)
                        j.begin_object()
                            .field("region", static_cast<std::int64_t>(o.region))
                            .field("area_m2", o.area_m2)
                            .field("fraction", o.fraction)
                            .end_object();
                    j.end_array().end_object();
                }
                j.end_array().end_object();
            }
            j.end_array().end_object();
            os.flush();
            if (!os) throw Error("write", "cannot write lineage.json");
            files.push_back("lineage.json");
        }
        // sweep.csv and sweep.png.
        std::vector<double> xs, counts, means;
        std::string csv =
            "area_ratio_percent,regions,critical_nodes,mean_region_area_m2,total_area_m2\n";
        for (const auto& s : scales) {
            double total = 0;
            for (const auto& r : s.regions.regions) total += r.area_m2;
            const double n = s.segmentation.region_count;
            const double mean = n > 0 ? total / n : 0;
            csv += s.name + "," + std::to_string(s.segmentation.region_count) + "," +
                   std::to_string(s.after.critical) + "," + JsonWriter::number(mean) + "," +
                   JsonWriter::number(total) + "\n";
            xs.push_back(s.ratio);
            counts.push_back(n);
            means.push_back(mean);
        }
        write_text(d + "sweep.csv", csv);
        files.push_back("sweep.csv");
        io::write_sweep_plot(xs, counts, means, d + "sweep.png", false);
        files.push_back("sweep.png");
        job.add_time("write",
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count());

        // run.json: the last scale stands in for the one-segmentation fields; every scale listed.
        job.segmentation = scales.back().segmentation;
        job.after = scales.back().after;
        std::string per_scale = "[";
        for (std::size_t i = 0; i < scales.size(); ++i) {
            const auto& s = scales[i];
            per_scale += std::string(i ? "," : "") + "{\"area_ratio_percent\":" + s.name +
                         ",\"regions\":" + std::to_string(s.segmentation.region_count) +
                         ",\"critical_nodes_after\":" + std::to_string(s.after.critical) +
                         ",\"relaxed_nodes\":" + std::to_string(s.segmentation.relaxed_nodes) +
                         ",\"seconds\":" + JsonWriter::number(s.seconds) + "}";
        }
        per_scale += "]";
        SegmentOptionValues recorded = segment_values;
        recorded.simplify.area_ratio = scales.back().ratio;
        write_run_json(job, common.input, field_values, recorded, files, d + "run.json",
                       {{"scales", per_scale}});
        dir.commit();
        report_progress(progress, 1.0);
        std::printf("%s: %zu scales;", common.output.c_str(), scales.size());
        for (const auto& s : scales)
            std::printf(" %s%%: %u regions;", s.name.c_str(), s.segmentation.region_count);
        std::printf(" %zu critical nodes before simplification\n", job.critical_before);
        if (segment_values.timings) print_timings(job.timings);
        return 0;
    });
}

}  // namespace terrain::cli
