#include "segment_job.hpp"

#include <malloc.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <type_traits>

#include "terrain/core/error.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/core/version.hpp"
#include "terrain/io/segment_outputs.hpp"
#include "terrain/io/temporary_files.hpp"

namespace terrain::cli {

namespace fs = std::filesystem;

namespace {

using clock = std::chrono::steady_clock;
double since(clock::time_point t0) {
    return std::chrono::duration<double>(clock::now() - t0).count();
}

}  // namespace

void SegmentJob::add_time(const std::string& name, double seconds) {
    for (auto& t : timings)
        if (t.name == name) {
            t.seconds += seconds;
            return;
        }
    timings.push_back({name, seconds});
}

void add_segment_options(po::options_description& options, SegmentOptionValues& values) {
    options.add_options()("persistence",
                          po::value(&values.simplify.persistence)->default_value(10.0),
                          "cancel arcs whose persistence is below P (field units)")(
        "area-ratio", po::value(&values.simplify.area_ratio)->default_value(0.5),
        "cancel arcs whose area ratio is below A percent of the surface")(
        "cost", po::value(&values.cost)->default_value("auto"),
        "graph (Reeb-graph constrained), standard, or auto: graph for DEMs, standard for meshes")(
        "saddle-penalty", po::value(&values.grow.saddle_penalty)->default_value(20.0),
        "graph cost: penalty for joining a saddle with several unassigned branches")(
        "format", po::value(&values.format)->default_value("GeoJSON"),
        "OGR driver of the region polygons (GeoJSON, GPKG, ...)")(
        "timings", po::bool_switch(&values.timings), "print the time of each stage");
}

void check_segment_options(const SegmentOptionValues& v) {
    if (!std::isfinite(v.simplify.persistence) || v.simplify.persistence < 0)
        throw Error("segment", "--persistence must be a number >= 0");
    if (!std::isfinite(v.simplify.area_ratio) || v.simplify.area_ratio < 0 ||
        v.simplify.area_ratio > 100)
        throw Error("segment", "--area-ratio is a percentage of the surface: between 0 and 100");
    if (!std::isfinite(v.grow.saddle_penalty) || v.grow.saddle_penalty < 0)
        throw Error("segment", "--saddle-penalty must be a number >= 0");
    if (v.cost != "auto") segment::parse_grow_cost(v.cost);
}

void compute_field(SegmentJob& job, const field::FieldOptions& options,
                   const ProgressFn& progress) {
    const auto t0 = clock::now();
    check_field_limits(options, job.input.mesh);
    job.field = field::vertex_field(job.input.mesh, job.dem(), options, progress);
    job.add_time("field", since(t0));
}

void compute_reeb(SegmentJob& job, const ProgressFn& progress) {
    const auto t0 = clock::now();
    job.graph = reeb::build_reeb_graph(job.input.mesh, job.field, {}, progress);
    job.critical_before = reeb::summarize(job.graph).critical;
    job.add_time("reeb", since(t0));
}

namespace {

// Regions grown on a simplified graph (cost auto: graph for DEMs, standard for meshes).
ScaleResult grow_scale(const SegmentJob& job, const SegmentOptionValues& values,
                       const reeb::SimplifyResult& simplified, double simplify_seconds,
                       const ProgressFn& progress) {
    ScaleResult out;
    out.after = reeb::summarize(simplified.graph);
    out.simplify_seconds = simplify_seconds;
    const auto t0 = clock::now();
    segment::GrowOptions grow = values.grow;
    grow.cost = values.cost == "auto"
                    ? (job.input.dem ? segment::GrowCost::graph : segment::GrowCost::standard)
                    : segment::parse_grow_cost(values.cost);
    out.segmentation = segment::grow_regions(job.input.mesh, simplified.graph, grow, progress);
    out.grow_seconds = since(t0);
    return out;
}

}  // namespace

ScaleResult segment_scale(const SegmentJob& job, const SegmentOptionValues& values,
                          const ProgressFn& progress) {
    const auto t0 = clock::now();
    const auto simplified = reeb::simplify(job.input.mesh, job.graph, values.simplify,
                                           scaled_progress(progress, 0, 0.3));
    return grow_scale(job, values, simplified, since(t0), scaled_progress(progress, 0.3, 1));
}

void segment_once(SegmentJob& job, const SegmentOptionValues& values, const ProgressFn& progress) {
    // One scale only: the simplification takes the graph and frees what it no longer needs,
    // which lowers the peak memory.
    const auto t0 = clock::now();
    const auto simplified = reeb::simplify(job.input.mesh, std::move(job.graph), values.simplify,
                                           scaled_progress(progress, 0, 0.3));
    const double seconds = since(t0);
    job.graph = reeb::ReebGraph();
    auto result = grow_scale(job, values, simplified, seconds, scaled_progress(progress, 0.3, 1));
    job.segmentation = std::move(result.segmentation);
    job.after = result.after;
    job.add_time("simplify", result.simplify_seconds);
    job.add_time("grow", result.grow_seconds);
}

std::vector<std::string> write_segmentation(SegmentJob& job, const SegmentOptionValues& values,
                                            const std::string& dir, const ProgressFn& progress,
                                            io::PreviewImage* deferred_preview) {
    const auto t0 = clock::now();
    job.regions = segment::region_graph(job.input.mesh, job.field, job.segmentation.labels,
                                        job.segmentation.region_count, job.dem());
    io::SegmentOutputOptions options;
    options.polygons.driver = values.format;
    options.deferred_preview = deferred_preview;
    auto paths = io::write_segment_outputs(dir, job.input.mesh, job.field, job.segmentation.labels,
                                           job.regions, job.dem(), options, progress);
    job.add_time("write", since(t0));
    std::vector<std::string> names;
    for (const auto& p : paths) names.push_back(fs::path(p).filename().string());
    return names;
}

MeshCounts mesh_counts(const TriangleMesh& mesh) {
    MeshCounts c;
    c.vertices = mesh.vertex_count();
    c.faces = mesh.triangle_count();
    const auto edges = static_cast<std::int64_t>(mesh.neighbors.size() / 2);
    c.boundary_edges = static_cast<std::size_t>(2 * edges - 3 * static_cast<std::int64_t>(c.faces));
    c.euler_characteristic =
        static_cast<std::int64_t>(c.vertices) - edges + static_cast<std::int64_t>(c.faces);
    return c;
}

void release_large_data(SegmentJob& job) {
    if (!job.mesh_counts) job.mesh_counts = mesh_counts(job.input.mesh);
    // (`v = {}` would keep a vector's capacity: it is the initializer-list assignment.)
    auto drop = [](auto& v) { std::decay_t<decltype(v)>().swap(v); };
    auto& m = job.input.mesh;
    drop(m.positions);
    drop(m.triangles);
    drop(m.vertex_areas);
    drop(m.neighbor_offsets);
    drop(m.neighbors);
    drop(m.vertex_pixel);
    drop(job.field);
    job.graph = reeb::ReebGraph();
    drop(job.segmentation.labels);
    drop(job.segmentation.seeds);
    malloc_trim(0);
}

void write_deferred_preview(SegmentJob& job, const io::PreviewImage& preview,
                            const std::string& dir) {
    const auto t0 = clock::now();
    io::write_preview_image(preview, (fs::path(dir) / "preview.png").string(), false);
    job.add_time("write", since(t0));
}

void write_run_json(const SegmentJob& job, const std::string& input_path,
                    const FieldOptionValues& field, const SegmentOptionValues& values,
                    const std::vector<std::string>& files, const std::string& path,
                    const std::vector<std::pair<std::string, std::string>>& extra) {
    std::ofstream os(path, std::ios::binary);
    if (!os) throw Error("write", "cannot write " + path);
    JsonWriter j(os);
    const auto topo = job.mesh_counts ? *job.mesh_counts : mesh_counts(job.input.mesh);
    const auto& after = job.after;
    j.begin_object();
    j.field("input", fs::absolute(input_path).lexically_normal().string());
    j.key("parameters")
        .begin_object()
        .field("field", field.name)
        .field("rings", field.options.shape_index.rings)
        .field("radius", field.options.shape_index.radius)
        .field("persistence", values.simplify.persistence)
        .field("area_ratio_percent", values.simplify.area_ratio)
        .field("cost",
               values.cost == "auto" ? (job.input.dem ? "graph" : "standard") : values.cost.c_str())
        .field("saddle_penalty", values.grow.saddle_penalty)
        .field("format", values.format)
        .field("frame", to_string(job.input.mesh.frame));
    if (field.name == "sdf")
        j.field("rays", field.options.sdf.rays)
            .field("cone_angle_degrees", field.cone_angle_degrees)
            .field("postprocess", !field.no_postprocess)
            .field("allow_open", field.options.sdf.allow_open);
    j.end_object();
    j.key("counts")
        .begin_object()
        .field("vertices", topo.vertices)
        .field("faces", topo.faces)
        .field("boundary_edges", topo.boundary_edges)
        .field("euler_characteristic", topo.euler_characteristic)
        .field("critical_nodes_before", job.critical_before)
        .field("critical_nodes_after", after.critical)
        .field("loops", after.loops)
        .field("regions", static_cast<std::size_t>(job.segmentation.region_count))
        .field("relaxed_nodes", job.segmentation.relaxed_nodes)
        .end_object();
    j.key("timings_seconds").begin_object();
    double total = 0;
    for (const auto& t : job.timings) {
        j.field(t.name, t.seconds);
        total += t.seconds;
    }
    j.field("total", total).end_object();
    j.key("outputs").begin_array();
    for (const auto& f : files) j.value(f);
    j.end_array();
    for (const auto& [k, v] : extra) j.key(k).raw(v);
    j.key("versions").begin_object().field("terrain", version());
    for (const auto& [name, v] : dependency_versions()) j.field(name, v);
    j.end_object();
    j.end_object();
    os.flush();
    if (!os) throw Error("write", "writing " + path + " failed (disk full?)");
}

void print_summary(const SegmentJob& job, const std::string& output, bool timings) {
    std::printf("%s: %u regions on %zu vertices (critical nodes %zu -> %zu)\n", output.c_str(),
                job.segmentation.region_count,
                job.mesh_counts ? job.mesh_counts->vertices : job.input.mesh.vertex_count(),
                job.critical_before, job.after.critical);
    if (timings) print_timings(job.timings);
}

void print_timings(const std::vector<StageTime>& timings) {
    double total = 0;
    std::printf("%-10s %10s\n", "stage", "seconds");
    for (const auto& t : timings) {
        std::printf("%-10s %10.3f\n", t.name.c_str(), t.seconds);
        total += t.seconds;
    }
    std::printf("%-10s %10.3f\n", "total", total);
}

OutputDirectory::OutputDirectory(std::string path, bool overwrite) : path_(std::move(path)) {
    std::error_code ec;
    const fs::path p = fs::path(path_).lexically_normal();
    if (p.filename().empty()) throw Error("write", "'" + path_ + "' is not a directory name");
    if (fs::exists(p, ec)) {
        if (!fs::is_directory(p, ec))
            throw Error("write", "'" + path_ + "' exists and is not a directory");
        if (!overwrite && !fs::is_empty(p, ec))
            throw Error("write", "'" + path_ + "' already exists; pass --overwrite to replace it");
    }
    const fs::path parent = p.has_parent_path() ? p.parent_path() : fs::path(".");
    if (!fs::is_directory(parent, ec))
        throw Error("write", "cannot write '" + path_ + "': '" + parent.string() +
                                 "' does not exist; create it first");
    if (::access(parent.c_str(), W_OK) != 0)
        throw Error("write",
                    "cannot create '" + path_ + "': '" + parent.string() + "' is not writable");
    temp_ = (parent / ("." + p.filename().string() + ".tmp" + std::to_string(::getpid()))).string();
    fs::remove_all(temp_, ec);
    io::remove_stale_temporaries(path_, true);
    if (!fs::create_directory(temp_, ec))
        throw Error("write", "cannot create a directory beside '" + path_ + "': " + ec.message());
}

OutputDirectory::~OutputDirectory() {
    if (committed_) return;
    std::error_code ec;
    fs::remove_all(temp_, ec);
}

void OutputDirectory::commit() {
    std::error_code ec;
    const std::string old = temp_ + ".old";
    const bool existed = fs::exists(path_, ec);
    if (existed) fs::rename(path_, old, ec);
    if (ec) throw Error("write", "cannot replace '" + path_ + "': " + ec.message());
    fs::rename(temp_, path_, ec);
    if (ec) {
        std::error_code ignored;
        if (existed) fs::rename(old, path_, ignored);
        throw Error("write", "cannot move the outputs into '" + path_ + "': " + ec.message());
    }
    committed_ = true;
    if (existed) fs::remove_all(old, ec);
}

}  // namespace terrain::cli
