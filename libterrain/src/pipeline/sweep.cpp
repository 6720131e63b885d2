#include "terrain/pipeline/sweep.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>

#include "terrain/core/error.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/core/memory_budget.hpp"
#include "terrain/io/write_adjacency.hpp"
#include "terrain/io/write_label_stack.hpp"
#include "terrain/io/write_mesh_labels.hpp"
#include "terrain/io/write_region_polygons.hpp"
#include "terrain/io/write_sweep_plot.hpp"

namespace terrain::pipeline {

namespace {

using clock = std::chrono::steady_clock;
double since(clock::time_point t0) {
    return std::chrono::duration<double>(clock::now() - t0).count();
}

void write_text(const std::string& path, const std::string& text) {
    std::ofstream f(path, std::ios::binary);
    f << text;
    f.flush();
    if (!f) throw Error("write", "cannot write " + path);
}

void check_ratios(const std::vector<double>& ratios) {
    if (ratios.empty()) throw Error("sweep", "--area-ratios needs at least one value");
    for (const double v : ratios)
        if (!std::isfinite(v) || v <= 0 || v > 100)
            throw Error("sweep",
                        "--area-ratios takes percentages in (0, 100] separated by commas; '" +
                            JsonWriter::number(v) + "' is not one");
}

}  // namespace

namespace {

// One scale to run: its area ratio, name and area threshold (0 for a sweep over ratios).
struct ScaleSpec {
    double ratio = 0;
    std::string name;
    double min_area_m2 = 0;
};

SweepResult run_sweep(Input input, const std::vector<ScaleSpec>& specs,
                      const SegmentOptions& options, const ProgressFn& progress);

}  // namespace

SweepResult sweep(Input input, const std::vector<double>& area_ratios,
                  const SegmentOptions& options, const ProgressFn& progress) {
    check_options(options);
    check_ratios(area_ratios);
    std::vector<double> ratios = area_ratios;
    std::sort(ratios.begin(), ratios.end());
    ratios.erase(std::unique(ratios.begin(), ratios.end()), ratios.end());
    std::vector<ScaleSpec> specs;
    for (const double r : ratios) specs.push_back({r, JsonWriter::number(r), 0});
    return run_sweep(std::move(input), specs, options, progress);
}

SweepResult sweep(Input input, const std::vector<AreaThreshold>& min_areas,
                  const SegmentOptions& options, const ProgressFn& progress) {
    check_options(options);
    if (min_areas.empty()) throw Error("sweep", "--min-areas needs at least one value");
    std::vector<AreaThreshold> areas = min_areas;
    for (const auto& a : areas)
        if (!std::isfinite(a.m2) || a.m2 <= 0)
            throw Error("sweep", "--min-areas takes areas above 0; '" + a.text + "' is not one");
    std::stable_sort(areas.begin(), areas.end(),
                     [](const AreaThreshold& a, const AreaThreshold& b) { return a.m2 < b.m2; });
    std::vector<ScaleSpec> specs;
    for (const auto& a : areas) {
        if (!specs.empty() && specs.back().min_area_m2 == a.m2) continue;
        specs.push_back({reeb::area_ratio_for_area(input.mesh, a.m2), a.text, a.m2});
    }
    return run_sweep(std::move(input), specs, options, progress);
}

namespace {

SweepResult run_sweep(Input input, const std::vector<ScaleSpec>& specs,
                      const SegmentOptions& options, const ProgressFn& progress) {
    SweepResult out;
    auto& base = out.base;
    base.input = std::move(input);
    base.add_time("read", base.input.read_seconds);
    if (base.input.dem) base.add_time("mesh", base.input.mesh_seconds);
    // The slices of the command line's bar (field 0.15-0.4, reeb -0.5, scales -0.75).
    compute_field(base, options, scaled_progress(progress, 0, 0.25 / 0.6));
    if (options.field_share.stop_after_field) return out;  // (a rank of the field only)
    const auto graph = compute_reeb(base, scaled_progress(progress, 0.25 / 0.6, 0.35 / 0.6));

    // Scale by scale, finest first, each simplification continuing from the previous scale's
    // graph: a coarser scale is a simplification of the finer one, so its extrema (and so its
    // regions' seeds) are among the finer one's. The first is `segment`'s at that threshold.
    // The absorbed vertices of a coarser scale go first with their finer region
    // (segment::divide_absorbed). Region tables are made while the next scale is simplified.
    auto& scales = out.scales;
    scales.resize(specs.size());
    const auto t0 = clock::now();
    reeb::SimplifyResult finer;  // the last scale simplified: the next one continues it
    tbb::task_group growing;
    try {
        for (std::size_t i = 0; i < specs.size(); ++i) {
            const auto s0 = clock::now();
            SegmentOptions scale_options = options;
            scale_options.simplify.area_ratio = specs[i].ratio;
            scale_options.simplify.rewrite_field = false;  // (nor does a sweep read it)
            scale_options.min_area = {};
            auto simplified = reeb::simplify(base.input.mesh, i == 0 ? graph : finer.graph,
                                             scale_options.simplify);
            // Absorbed at this scale or a finer one.
            if (i > 0)
                for (std::size_t v = 0; v < simplified.absorbed.size(); ++v)
                    simplified.absorbed[v] |= finer.absorbed[v];
            finer = std::move(simplified);  // and the finer scale's is freed
            auto result = grow_simplified(base.input, base.field, scale_options, finer,
                                          i == 0 ? nullptr : &scales[i - 1].segmentation.labels);
            auto& scale = scales[i];
            scale.ratio = specs[i].ratio;
            scale.name = specs[i].name;
            scale.min_area_m2 = specs[i].min_area_m2;
            scale.after = result.after;
            scale.segmentation = std::move(result.segmentation);
            const double seconds = since(s0);
            report_progress(progress, (0.35 + 0.25 * double(i + 1) / double(specs.size())) / 0.6,
                            "sweep");
            growing.run([&, i, seconds] {
                const auto g0 = clock::now();
                auto& done = scales[i];
                done.regions =
                    segment::region_graph(base.input.mesh, base.field, done.segmentation.labels,
                                          done.segmentation.region_count, base.dem());
                done.seconds = seconds + since(g0);
            });
        }
    } catch (...) {
        growing.wait();
        throw;
    }
    growing.wait();
    finer = {};
    // On a DEM, with the regions of valid pixels in no triangle (segment::label_pixels).
    for (auto& scale : scales)
        scale.segmentation.region_count = static_cast<std::uint32_t>(scale.regions.regions.size());
    // lineage: scale i -> scale i+1.
    out.lineage.resize(scales.empty() ? 0 : scales.size() - 1);
    tbb::parallel_for(std::size_t{0}, out.lineage.size(), [&](std::size_t i) {
        const auto& a = scales[i];
        const auto& b = scales[i + 1];
        out.lineage[i] = segment::region_lineage(base.input.mesh, base.dem(), a.segmentation.labels,
                                                 a.segmentation.region_count, b.segmentation.labels,
                                                 b.segmentation.region_count);
    });
    base.add_time("scales", since(t0));
    report_progress(progress, 1.0);
    return out;
}

}  // namespace

namespace {

// A DEM's sweep: every scale's labels in one raster of bands, and its polygons (a layer each
// in the GeoPackage, a GeoJSON file each); progress 0.2 after the labels.
void write_scale_maps(const SweepResult& result, const Dem& dem, const std::string& dir_path,
                      std::vector<std::string>& files, const ProgressFn& progress) {
    const auto& base = result.base;
    const auto& scales = result.scales;
    const std::string d = dir_path + "/";
    std::vector<std::vector<std::uint32_t>> bands;
    std::vector<std::string> descriptions;
    std::vector<const segment::RegionGraph*> graphs;
    for (const auto& s : scales) {
        graphs.push_back(&s.regions);
        bands.push_back(segment::label_pixels(base.input.mesh, dem, s.segmentation.labels));
        descriptions.push_back((s.min_area_m2 > 0 ? "min_area=" : "area_ratio=") + s.name);
    }
    io::write_label_stack(dem, bands, descriptions, graphs, d + "labels.tif", false);
    files.push_back("labels.tif");
    files.push_back("labels.qml");
    report_progress(progress, 0.2);
    // Each scale polygonized once; then the GeoPackage's layers one after the other,
    // the GeoJSON files beside them.
    std::vector<io::RegionPolygons> polygons(scales.size());
    tbb::parallel_for(std::size_t{0}, scales.size(), [&](std::size_t i) {
        polygons[i] =
            io::polygonize_regions(dem, bands[i], scales[i].regions.regions.size(), dir_path);
    });
    tbb::parallel_invoke(
        [&] {
            for (std::size_t i = 0; i < scales.size(); ++i) {
                io::RegionPolygonOptions gpkg;
                gpkg.driver = "GPKG";
                gpkg.layer = "regions_" + scales[i].name;
                gpkg.append_layer = true;
                io::write_region_polygons(dem, polygons[i], scales[i].regions, d + "regions.gpkg",
                                          false, gpkg);
            }
        },
        [&] {
            tbb::parallel_for(std::size_t{0}, scales.size(), [&](std::size_t i) {
                io::write_region_polygons(dem, polygons[i], scales[i].regions,
                                          d + "regions_" + scales[i].name + ".geojson", false);
            });
        });
    files.push_back("regions.gpkg");
    for (const auto& s : scales) files.push_back("regions_" + s.name + ".geojson");
}

// lineage.json: each scale's region in the next scale's, with their overlaps.
void write_lineage_json(const SweepResult& result, const std::string& path, bool by_area,
                        bool dem) {
    const auto& scales = result.scales;
    std::ofstream os(path, std::ios::binary);
    JsonWriter j(os);
    j.begin_object();
    j.key("scales").begin_array();
    for (const auto& s : scales) j.value(s.ratio);
    j.end_array();
    if (by_area) {
        j.key("min_areas_m2").begin_array();
        for (const auto& s : scales) j.value(s.min_area_m2);
        j.end_array();
    }
    j.field("area_unit", dem ? "m^2 of pixel footprints on the body" : "m^2 of mesh surface");
    j.key("links").begin_array();
    for (std::size_t i = 0; i < result.lineage.size(); ++i) {
        const auto& a = scales[i];
        const auto& b = scales[i + 1];
        j.begin_object()
            .field("from_area_ratio", a.ratio)
            .field("to_area_ratio", b.ratio)
            .field("mean_parent_share", segment::mean_parent_share(result.lineage[i]));
        j.key("regions").begin_array();
        for (const auto& r : result.lineage[i]) {
            j.begin_object()
                .field("region", static_cast<std::int64_t>(r.region))
                .field("area_m2", r.area_m2)
                .field("parent", static_cast<std::int64_t>(r.parent))
                .field("parent_share", r.parent_share);
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
}

// sweep.csv and sweep.png: each scale's regions, critical nodes and mean region area.
void write_sweep_table(const std::vector<SweepScale>& scales, const std::string& d, bool by_area,
                       std::vector<std::string>& files) {
    std::vector<double> xs, counts, means;
    std::string csv = std::string(
                          "area_ratio_percent,regions,critical_nodes,mean_region_area_m2,"
                          "total_area_m2") +
                      (by_area ? ",min_area_m2\n" : "\n");
    for (const auto& s : scales) {
        double total = 0;
        for (const auto& r : s.regions.regions) total += r.area_m2;
        const double n = s.segmentation.region_count;
        const double mean = n > 0 ? total / n : 0;
        csv += JsonWriter::number(s.ratio) + "," + std::to_string(s.segmentation.region_count) +
               "," + std::to_string(s.after.critical) + "," + JsonWriter::number(mean) + "," +
               JsonWriter::number(total) +
               (by_area ? "," + JsonWriter::number(s.min_area_m2) + "\n" : "\n");
        xs.push_back(s.ratio);
        counts.push_back(n);
        means.push_back(mean);
    }
    write_text(d + "sweep.csv", csv);
    files.push_back("sweep.csv");
    io::write_sweep_plot(xs, counts, means, d + "sweep.png", false);
    files.push_back("sweep.png");
}

// run.json's "scales": each scale's ratio (and minimum area), regions, nodes and time.
std::string per_scale_json(const std::vector<SweepScale>& scales, bool by_area) {
    std::string per_scale = "[";
    for (std::size_t i = 0; i < scales.size(); ++i) {
        const auto& s = scales[i];
        per_scale += std::string(i ? "," : "") +
                     "{\"area_ratio_percent\":" + JsonWriter::number(s.ratio) +
                     (by_area ? ",\"min_area\":" + JsonWriter::escape(s.name) +
                                    ",\"min_area_m2\":" + JsonWriter::number(s.min_area_m2)
                              : std::string()) +
                     ",\"regions\":" + std::to_string(s.segmentation.region_count) +
                     ",\"critical_nodes_after\":" + std::to_string(s.after.critical) +
                     ",\"relaxed_nodes\":" + std::to_string(s.segmentation.relaxed_nodes) +
                     ",\"seconds\":" + JsonWriter::number(s.seconds) + "}";
    }
    per_scale += "]";
    return per_scale;
}

}  // namespace

std::vector<std::string> write_sweep_directory(SweepResult& result, const SegmentOptions& options,
                                               const std::string& input_path,
                                               const std::string& dir_path,
                                               const ProgressFn& progress) {
    auto& base = result.base;
    const auto& scales = result.scales;
    const std::string d = dir_path + "/";
    const auto w0 = clock::now();
    release_free_memory();  // (freed blocks a program keeps: GDAL's block cache comes next)
    std::vector<std::string> files;
    const Dem* dem = base.dem();
    const bool by_area = !scales.empty() && scales.front().min_area_m2 > 0;
    if (dem) {
        write_scale_maps(result, *dem, dir_path, files, progress);
    } else {
        for (const auto& s : scales) {
            io::write_faces_seg(base.input.mesh, s.segmentation.labels,
                                d + "faces_" + s.name + ".seg", false);
            files.push_back("faces_" + s.name + ".seg");
        }
    }
    report_progress(progress, 0.7);
    for (const auto& s : scales) {
        io::write_adjacency_json(s.regions, d + "adjacency_" + s.name + ".json", false);
        files.push_back("adjacency_" + s.name + ".json");
    }
    write_lineage_json(result, d + "lineage.json", by_area, dem != nullptr);
    files.push_back("lineage.json");
    write_sweep_table(scales, d, by_area, files);
    base.add_time("write", since(w0));

    // run.json: the last scale stands in for the one-segmentation fields; every scale listed.
    if (!scales.empty()) {
        base.segmentation.region_count = scales.back().segmentation.region_count;
        base.segmentation.relaxed_nodes = scales.back().segmentation.relaxed_nodes;
        base.after = scales.back().after;
    }
    const std::string per_scale = per_scale_json(scales, by_area);
    SegmentOptions recorded = options;
    recorded.min_area = {};
    if (!scales.empty()) {
        recorded.simplify.area_ratio = scales.back().ratio;
        base.area_ratio_percent = scales.back().ratio;
        if (by_area)
            recorded.min_area = MinArea::area(scales.back().min_area_m2, scales.back().name);
    }
    write_run_json(base, input_path, recorded, files, d + "run.json", {{"scales", per_scale}});
    files.push_back("run.json");
    report_progress(progress, 1.0);
    return files;
}

}  // namespace terrain::pipeline
