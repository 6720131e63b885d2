#include "terrain/pipeline/segment.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <type_traits>

#include "packed_heights.hpp"
#include "parked_arrays.hpp"
#include "region_scales.hpp"
#include "stage_clock.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/huge_pages.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/core/memory_budget.hpp"
#include "terrain/core/version.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/release.hpp"
#include "terrain/internal/core/significant.hpp"
#include "terrain/io/dependency_versions.hpp"
#include "terrain/io/mesh_files.hpp"
#include "terrain/io/write_craters.hpp"
#include "terrain/io/write_label_raster.hpp"
#include "terrain/io/write_preview.hpp"
#include "terrain/io/write_region_polygons.hpp"
#include "terrain/io/write_segment_outputs.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/pipeline/memory_plan.hpp"
#include "terrain/segment/area_range.hpp"

namespace terrain::pipeline {

namespace fs = std::filesystem;

using internal::clock;
using internal::PackedHeights;
using internal::since;

std::vector<std::string> georeference_warnings(const Dem& dem) {
    const std::string name = "'" + (dem.source.empty() ? std::string("the DEM") : dem.source) + "'";
    if (!dem.has_transform) {
        const double size = std::abs(dem.transform[1]);
        const bool given = size != 1.0 || std::abs(dem.transform[5]) != 1.0;
        return {name + " has no geotransform: its pixels are taken as " + (given ? "" : "1 m ") +
                "squares" + (given ? " of the given --pixel-size" : " (give --pixel-size)") +
                " and the outputs are in local metres, with no longitude/latitude"};
    }
    if (dem.crs_wkt.empty())
        return {name +
                " has no CRS: the outputs are in its local map metres, with no "
                "longitude/latitude"};
    return {};
}

MeshCounts mesh_counts(const TriangleMesh& mesh) {
    MeshCounts c;
    c.vertices = mesh.vertex_count();
    c.faces = mesh.triangle_count();
    const auto edges = static_cast<std::int64_t>(mesh.edge_count());
    c.boundary_edges = static_cast<std::size_t>(2 * edges - 3 * static_cast<std::int64_t>(c.faces));
    c.euler_characteristic =
        static_cast<std::int64_t>(c.vertices) - edges + static_cast<std::int64_t>(c.faces);
    return c;
}

void SegmentResult::add_time(const std::string& name, double seconds) {
    for (auto& t : timings)
        if (t.name == name) {
            t.seconds += seconds;
            return;
        }
    timings.push_back({name, seconds});
}

std::vector<std::uint32_t> SegmentResult::label_pixels() const {
    if (!input.dem) throw Error("segment", "label pixels need a DEM; this input is a mesh file");
    return segment::label_pixels(input.mesh, *input.dem, segmentation.labels);
}

void compute_field(SegmentResult& result, const SegmentOptions& options,
                   const ProgressFn& progress) {
    const auto t0 = clock::now();
    const auto fo = field_options(options);
    if (fo.kind == field::FieldKind::shape_index && fo.shape_index.auto_scale) {
        auto selected =
            field::scale_selected_shape_index(result.input.mesh, fo.shape_index, progress);
        result.field = std::move(selected.field);
        result.field_scale = std::move(selected.scale);
        result.field_radii = std::move(selected.radii);
        result.pixel_noise_m = selected.pixel_noise_m;
    } else {
        result.field = field::vertex_field(result.input.mesh, result.dem(), fo, progress);
    }
    if (options.field == field::FieldKind::shape_index) {
        result.shape_index_method =
            field::shape_index_method(result.input.mesh, options.shape_index);
        result.shape_index_window =
            field::shape_index_window(result.input.mesh, options.shape_index);
    }
    result.add_time("field", since(t0));
}

reeb::ReebGraph compute_reeb(SegmentResult& result, const ProgressFn& progress, bool known_tree,
                             const std::function<void()>& field_read,
                             const reeb::ArrayParking& sweeps) {
    const auto t0 = clock::now();
    auto& mesh = result.input.mesh;
    // A DEM mesh frees its triangles (24 bytes a pixel) once no stage needs them at random,
    // and the stages after make them again from the grid, in order. When the Reeb graph is a
    // tree (every component a disk or a sphere: the contour tree makes it) that is before it;
    // with loops the contour-tracking sweep walks them at random, so after.
    if (!known_tree && mesh.triangles_releasable() &&
        reeb::reeb_is_tree(mesh, scaled_progress(progress, 0, 0.1))) {
        mesh.release_triangles();
        known_tree = true;
    }
    reeb::ReebOptions reeb_options;
    reeb_options.known_tree = known_tree;
    reeb_options.field_read = field_read;
    reeb_options.sweeps = sweeps;
    auto graph = reeb::build_reeb_graph(mesh, result.field, reeb_options,
                                        scaled_progress(progress, 0.1, 0.95));
    // Only the count of critical nodes is reported: summarize() would also count the graph's
    // components and loops, a union-find over every node (about 1.5 % of a whole run).
    result.critical_before = static_cast<std::size_t>(
        std::count_if(graph.node_kinds.begin(), graph.node_kinds.end(),
                      [](reeb::NodeKind k) { return k != reeb::NodeKind::regular; }));
    report_progress(progress, 1.0, "reeb");
    mesh.release_triangles();
    result.add_time("reeb", since(t0));
    return graph;
}

namespace {

// What the growing calls between its steps (segment::DivideHooks): graph_read once it reads
// the simplified graph and its absorbed flags no more, with the regions as grown and a slice
// of the progress (the field and the mesh's positions are read after it; the labels as grown
// not until labels_read is called).
struct GrowHooks {
    std::function<void(segment::Segmentation&, const ProgressFn&)> graph_read;
    std::function<void(segment::Segmentation&)> labels_read;
};

// Regions grown on a simplified graph.
ScaleResult grow_scale(const Input& input, const std::vector<float>& field,
                       const SegmentOptions& options, const reeb::SimplifyResult& simplified,
                       double simplify_seconds, const ProgressFn& progress,
                       const std::vector<std::uint32_t>* finer = nullptr,
                       const GrowHooks& grow_hooks = {}) {
    ScaleResult out;
    out.after = reeb::summarize(simplified.graph);
    out.simplify_seconds = simplify_seconds;
    const auto t0 = clock::now();
    segment::GrowOptions grow;
    grow.saddle_penalty = options.saddle_penalty;
    grow.cost = grow_cost(options, input.dem.has_value());
    const bool divide = absorbed_mode(options, input.dem.has_value()) == Absorbed::divide;
    out.segmentation = segment::grow_regions(input.mesh, simplified.graph, grow,
                                             scaled_progress(progress, 0, divide ? 0.5 : 1));
    segment::DivideHooks hooks;
    if (grow_hooks.graph_read)
        hooks.seed_parts_kept = [&](const ProgressFn& slice) {
            grow_hooks.graph_read(out.segmentation, slice);
        };
    if (grow_hooks.labels_read) hooks.flooded = [&] { grow_hooks.labels_read(out.segmentation); };
    if (divide) {
        out.divided = segment::divide_absorbed(input.mesh, simplified.graph, field,
                                               simplified.absorbed, out.segmentation, finer,
                                               scaled_progress(progress, 0.5, 1), hooks);
    } else {
        if (hooks.seed_parts_kept) hooks.seed_parts_kept(scaled_progress(progress, 1, 1));
        if (hooks.flooded) hooks.flooded();
    }
    out.grow_seconds = since(t0);
    return out;
}

}  // namespace

ScaleResult grow_simplified(const Input& input, const std::vector<float>& field,
                            const SegmentOptions& options, const reeb::SimplifyResult& simplified,
                            const std::vector<std::uint32_t>* finer, const ProgressFn& progress) {
    return grow_scale(input, field, options, simplified, 0, progress, finer);
}

ScaleResult segment_scale(const Input& input, const std::vector<float>& field,
                          const reeb::ReebGraph& graph, const SegmentOptions& options,
                          const ProgressFn& progress) {
    const auto t0 = clock::now();
    const auto simplified = reeb::simplify(input.mesh, graph, simplify_options(options, input.mesh),
                                           scaled_progress(progress, 0, 0.3));
    return grow_scale(input, field, options, simplified, since(t0),
                      scaled_progress(progress, 0.3, 1));
}

namespace {

// segment()'s progress: one slice a stage, by the stages' measured cost on global grids of 1
// to 66 M pixels (docs/performance.md): the field 0.2, the Reeb graph 0.2, the simplification
// 0.2 (with the arrays parked before it), the growing and the division 0.3, the region graph
// 0.1. Arrays parked or brought back between stages take a hundredth or two of the slice
// they belong to; at(slice, t) is the point t of the way through a slice.
struct Slice {
    double from, to;
};
constexpr Slice kFieldSlice{0, 0.2};    // the tree check, the DEM held, the field
constexpr Slice kReebSlice{0.2, 0.4};   // the vertices' areas parked, the Reeb graph
constexpr Slice kParkSlice{0.4, 0.41};  // the field and the pixel maps parked
constexpr Slice kSimplifySlice{0.41, 0.6};
constexpr Slice kRestoreSlice{0.6, 0.62};  // the areas and the adjacency back
constexpr Slice kGrowSlice{0.62, 0.9};     // growing, area ranges, division
constexpr Slice kRegionsSlice{0.9, 1};     // the scales and the DEM back, the region graph
constexpr double at(const Slice& slice, double t) {
    return slice.from + t * (slice.to - slice.from);
}
ProgressFn slice_of(const ProgressFn& progress, const Slice& slice, double t0 = 0, double t1 = 1) {
    return scaled_progress(progress, at(slice, t0), at(slice, t1));
}

// One run of pipeline::segment: the result as it is made, and the arrays that wait unread
// through the stages that do not read them: the DEM's values (as floats when they all are
// floats), then the field and the mesh's pixel maps, parked on disk (parked_arrays.hpp;
// docs/performance.md, "Arrays parked on disk") when large. The DEM waits from before the
// field (only the height field reads it) to the placing of the positions (once the growing
// has read the simplified graph for the last time), and again through the division of the
// absorbed vertices. Whether to park at all is decided the first time, on what all the arrays
// parked through the run hold (the field is a float a vertex).
class SegmentRun {
  public:
    SegmentRun(SegmentResult& result, const SegmentOptions& options, const ProgressFn& progress)
        : result_(result),
          options_(options),
          progress_(progress),
          mesh_(result.input.mesh),
          parked_(options.park_directory, options.park_min_bytes) {}

    // The field, the DEM held from before it unless it reads it; kFieldSlice. Returns
    // whether the Reeb graph is known to be a tree.
    bool field();
    // The Reeb graph, the arrays it does not read waiting; kReebSlice.
    reeb::ReebGraph reeb(bool tree);
    // The simplification, the arrays it does not read waiting; kSimplifySlice.
    reeb::SimplifyResult simplify(reeb::ReebGraph graph, const reeb::SimplifyOptions& thresholds);
    // The arrays the growing on the graph reads back (the vertices' areas, the adjacency's);
    // kRestoreSlice. Returns its time.
    double restore_for_growing();
    // The rest back for the division of the absorbed vertices: the field, the positions
    // placed again (the vertices' areas waiting meanwhile), the DEM waiting again; progress 0
    // to 1 of `progress`.
    void restore_for_dividing(const ProgressFn& progress);
    // The region graph, its scales and area ranges, the craters; kRegionsSlice. Returns
    // its time.
    double regions(const std::vector<double>& ranges);

    internal::ParkedArrays& parked() { return parked_; }

  private:
    void hold_dem(const ProgressFn& held);
    void restore_dem(const ProgressFn& back);

    SegmentResult& result_;
    const SegmentOptions& options_;
    const ProgressFn& progress_;
    TriangleMesh& mesh_;
    PackedHeights packed_;
    internal::ParkedArrays parked_;
    bool placed_again_ = false;  // the positions freed through the Reeb graph
};

void SegmentRun::hold_dem(const ProgressFn& held) {
    Dem& dem = *result_.input.dem;
    packed_.pack(dem, scaled_progress(held, 0, 0.5));
    if (!parked_.decided())
        parked_.decide(packed_.bytes(dem) +
                       sizeof(float) * (mesh_.vertex_count() + mesh_.vertex_areas.size()) +
                       sizeof(std::int32_t) *
                           (mesh_.pixel_vertex.size() + mesh_.vertex_pixel.size()) +
                       mesh_.neighbor_directions.size());
    if (!packed_.park(parked_, scaled_progress(held, 0.5, 1)))
        parked_.park(dem.values, held, 0.5, 1);
}

// The DEM back as doubles.
void SegmentRun::restore_dem(const ProgressFn& back) {
    parked_.restore(result_.input.dem->values, back, 0, 0.2);
    packed_.restore(parked_, scaled_progress(back, 0, 0.2));
    packed_.unpack(*result_.input.dem, scaled_progress(back, 0.2, 1));
}

bool SegmentRun::field() {
    auto& result = result_;
    auto& mesh = mesh_;
    const auto& options = options_;
    const auto& progress = progress_;
    // A DEM mesh whose Reeb graph is a tree (every component a disk or a sphere) frees its
    // triangles (24 bytes a pixel) before the field: no stage reads them at random, the
    // shape index's normals and the later stages walk them again from the grid in order.
    // The SDF casts rays through them: it keeps them. (The loop check is counted with the
    // field, which it precedes.)
    const auto tf = clock::now();
    const auto kind = options.field;
    const bool tree = kind != field::FieldKind::sdf &&
                      (mesh.triangles_released() || mesh.triangles_releasable()) &&
                      reeb::reeb_is_tree(mesh, slice_of(progress, kFieldSlice, 0, 0.1));
    if (tree)
        mesh.release_triangles();
    else
        mesh.restore_triangles();  // (released by load_input: the Reeb graph reads them)
    result.add_time("field", since(tf));
    const bool field_reads_dem = kind == field::FieldKind::height;
    if (result.input.dem && !field_reads_dem) hold_dem(slice_of(progress, kFieldSlice, 0.1, 0.15));
    result.parked_field = parked_.parked_bytes();
    compute_field(
        result, options,
        slice_of(progress, kFieldSlice, field_reads_dem ? 0.1 : 0.15, field_reads_dem ? 0.95 : 1));
    // A DEM mesh frees its positions (12 bytes a vertex) while the Reeb graph and the
    // simplification run, which do not read them, and places them again before the growing:
    // the same floats (docs/mesh.md, "Positions freed and placed again").
    placed_again_ = result.input.dem && mesh.release_positions();
    const auto tp = clock::now();
    if (result.input.dem) {
        if (field_reads_dem) hold_dem(slice_of(progress, kFieldSlice, 0.95, 1));
        // The vertices' areas wait through the Reeb graph, which does not read them (the
        // simplification does).
        parked_.park(mesh.vertex_areas, progress, at(kReebSlice, 0), at(kReebSlice, 0.05));
    }
    result.add_time("reeb", since(tp));  // (which it precedes: the times stay in run order)
    return tree;
}

reeb::ReebGraph SegmentRun::reeb(bool tree) {
    auto& result = result_;
    auto& mesh = mesh_;
    auto& parked = parked_;
    const auto& progress = progress_;
    // The field waits on disk too once the Reeb graph's events are ordered (the contour tree
    // does not read it): the Reeb graph's peak of memory is in the contour tree.
    // The graph's vertex lists, vertices' nodes and node values wait too through the contour
    // tree's join and split sweeps (its peak, the two side by side), which do not read them,
    // and so do the mesh's pixel maps.
    reeb::ArrayParking sweeps;
    sweeps.park = [&](std::vector<std::int32_t>& v) { parked.park(v, {}, 0, 0); };
    sweeps.restore = [&](std::vector<std::int32_t>& v) { parked.restore(v, {}, 0, 0); };
    sweeps.park_floats = [&](std::vector<float>& v) { parked.park(v, {}, 0, 0); };
    sweeps.restore_floats = [&](std::vector<float>& v) { parked.restore(v, {}, 0, 0); };
    sweeps.park_own = [&] {
        parked.park(mesh.pixel_vertex, {}, 0, 0);
        parked.park(mesh.vertex_pixel, {}, 0, 0);
    };
    sweeps.restore_own = [&] {
        parked.restore(mesh.vertex_pixel, {}, 0, 0);
        parked.restore(mesh.pixel_vertex, {}, 0, 0);
    };
    auto graph = compute_reeb(
        result, slice_of(progress, kReebSlice, 0.05, 1), tree,
        [&] {
            parked.park(result.field, {}, 0, 0);
            parked.park(result.field_scale, {}, 0, 0);
        },
        sweeps);
    const auto ta = clock::now();
    parked.restore(mesh.vertex_areas, progress, kReebSlice.to, kReebSlice.to);
    result.add_time("reeb", since(ta));
    return graph;
}

reeb::SimplifyResult SegmentRun::simplify(reeb::ReebGraph graph,
                                          const reeb::SimplifyOptions& thresholds) {
    auto& result = result_;
    auto& mesh = mesh_;
    auto& parked = parked_;
    const auto& progress = progress_;
    // The areas wait on disk again once the simplification has read them, and the graph's
    // vertices' nodes until its output reads them (both before its peak of memory, the end
    // of its copy of the arcs). (Parked without progress: the simplification reports around
    // it.)
    reeb::VertexNodesParking vertex_nodes;
    vertex_nodes.park = [&](std::vector<std::int32_t>& v) {
        if (parked.park(v, {}, 0, 0)) result.parked_bytes = parked.parked_bytes();
    };
    vertex_nodes.restore = [&](std::vector<std::int32_t>& v) { parked.restore(v, {}, 0, 0); };
    auto simplified = reeb::simplify(
        result.input.mesh, std::move(graph), thresholds, slice_of(progress, kSimplifySlice),
        [&] {
            if (parked.park(mesh.vertex_areas, {}, 0, 0))
                result.parked_bytes = parked.parked_bytes();
        },
        vertex_nodes);
    return simplified;
}

double SegmentRun::restore_for_growing() {
    auto& mesh = mesh_;
    auto& parked = parked_;
    const auto& progress = progress_;
    const auto t2 = clock::now();
    parked.restore(mesh.vertex_areas, progress, at(kRestoreSlice, 0), at(kRestoreSlice, 0.25));
    parked.restore(mesh.neighbor_directions, progress, at(kRestoreSlice, 0.25),
                   at(kRestoreSlice, 0.5));
    parked.restore(mesh.vertex_pixel, progress, at(kRestoreSlice, 0.5), at(kRestoreSlice, 0.75));
    parked.restore(mesh.pixel_vertex, progress, at(kRestoreSlice, 0.75), kRestoreSlice.to);
    return since(t2);
}

void SegmentRun::restore_for_dividing(const ProgressFn& progress) {
    auto& result = result_;
    auto& mesh = mesh_;
    auto& parked = parked_;
    // The vertices' areas wait while the positions are placed (the division reads them
    // after).
    parked.park(mesh.vertex_areas, progress, 0, 0);
    parked.restore(result.field, progress, 0, 0.1);
    // The DEM back as doubles for the placing of the positions, then waiting again through
    // the division, which does not read it; back for the region graph's points.
    if (result.input.dem) restore_dem(scaled_progress(progress, 0.1, 0.4));
    if (placed_again_)
        mesh::restore_positions(*result.input.dem, mesh, scaled_progress(progress, 0.4, 0.8));
    if (result.input.dem && parked.on()) hold_dem(scaled_progress(progress, 0.8, 1));
    parked.restore(mesh.vertex_areas, progress, 1, 1);
    result.parked_growing = parked.parked_bytes();
}

double SegmentRun::regions(const std::vector<double>& ranges) {
    auto& result = result_;
    auto& mesh = mesh_;
    const auto& options = options_;
    const auto& progress = progress_;
    const auto t1 = clock::now();
    parked_.restore(result.field_scale, progress, kRegionsSlice.from, kRegionsSlice.from);
    if (result.input.dem) restore_dem(slice_of(progress, kRegionsSlice, 0, 0.05));
    result.regions = segment::region_graph(
        result.input.mesh, result.field, result.segmentation.labels,
        result.segmentation.region_count, result.dem(), slice_of(progress, kRegionsSlice, 0.05, 1));
    // On a DEM, with the regions of valid pixels in no triangle (segment::label_pixels).
    result.segmentation.region_count = static_cast<std::uint32_t>(result.regions.regions.size());
    internal::set_region_scales(result);
    if (options.min_area.is_auto()) internal::set_area_ranges(result, ranges);
    if (options.craters && result.input.dem)
        result.craters = segment::find_craters(mesh, *result.input.dem, result.segmentation.labels,
                                               result.regions);
    return since(t1);
}

}  // namespace

SegmentResult segment(Input input, const SegmentOptions& requested, const ProgressFn& progress) {
    check_options(requested);
    const SegmentOptions options = resolve_options(requested, input.dem.has_value());
    // A polygon format that cannot hold the DEM's coordinates is refused before any work.
    if (input.dem) io::check_polygon_format(*input.dem, options.format);
    SegmentResult result;
    result.input = std::move(input);
    result.timings.push_back({"read", result.input.read_seconds});
    if (result.input.dem) result.timings.push_back({"mesh", result.input.mesh_seconds});
    // The stages in turn, each in its slice of the progress (kFieldSlice ... kRegionsSlice).
    SegmentRun run(result, options, progress);
    auto& mesh = result.input.mesh;
    const bool tree = run.field();
    auto graph = run.reeb(tree);
    // One scale only: the simplification takes the graph and frees what it no longer needs,
    // which lowers the peak memory.
    const auto t0 = clock::now();
    if (run.parked().on()) {
        auto& parked = run.parked();
        if (!result.field.empty())
            parked.park(result.field, progress, at(kParkSlice, 0), at(kParkSlice, 0.3));
        parked.park(mesh.pixel_vertex, progress, at(kParkSlice, 0.3), at(kParkSlice, 0.6));
        parked.park(mesh.vertex_pixel, progress, at(kParkSlice, 0.6), at(kParkSlice, 0.9));
        parked.park(mesh.neighbor_directions, progress, at(kParkSlice, 0.9), kParkSlice.to);
    }
    result.parked_bytes = run.parked().parked_bytes();
    const auto thresholds = simplify_options(options, result.input.mesh);
    result.area_ratio_percent = thresholds.area_ratio;
    result.min_area_m2 = min_area_m2(options, result.input.mesh);
    auto simplified = run.simplify(std::move(graph), thresholds);
    const double seconds = since(t0);
    // (Counted with the growing, which it precedes: the stages' times stay in run order.)
    const double placing = run.restore_for_growing();
    // Once the growing has read the simplified graph for the last time: the regions' range
    // of area thresholds, simplifying the graph on (counted with the simplification; the
    // graph goes as it is read), then the arrays the division reads back. The absorbed flags
    // go too.
    std::vector<double> ranges;
    double range_seconds = 0;
    GrowHooks hooks;
    hooks.graph_read = [&](segment::Segmentation& grown, const ProgressFn& slice) {
        detail::release(simplified.absorbed);
        const auto tr = clock::now();
        if (options.min_area.is_auto()) {
            segment::AreaRangeOptions range;
            range.floor_m2 = result.min_area_m2;
            range.persistence = thresholds.persistence;
            ranges = segment::seed_area_ranges(mesh, std::move(simplified.graph), grown.seeds,
                                               range, scaled_progress(slice, 0, 0.6));
        }
        simplified.graph = reeb::ReebGraph{};
        range_seconds = since(tr);
        // The labels as grown wait through the division's flooding, which does not read them.
        run.parked().park(grown.labels, {}, 0, 0);
        run.restore_for_dividing(scaled_progress(slice, 0.6, 1));
    };
    hooks.labels_read = [&](segment::Segmentation& grown) {
        run.parked().restore(grown.labels, {}, 0, 0);
    };
    auto scale = grow_scale(result.input, result.field, options, simplified, seconds,
                            slice_of(progress, kGrowSlice), nullptr, hooks);
    result.segmentation = std::move(scale.segmentation);
    result.after = scale.after;
    result.divided = scale.divided;
    result.add_time("simplify", scale.simplify_seconds + range_seconds);
    simplified = reeb::SimplifyResult{};
    const double region_seconds = run.regions(ranges);
    result.add_time("grow", placing + scale.grow_seconds - range_seconds + region_seconds);
    result.parked_file = run.parked().file_peak();
    result.parked_most = run.parked().most_parked();
    return result;
}

}  // namespace terrain::pipeline
