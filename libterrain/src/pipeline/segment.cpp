#include "terrain/pipeline/segment.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <type_traits>

#include "packed_heights.hpp"
#include "region_scales.hpp"
#include "stage_clock.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/huge_pages.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/core/memory_budget.hpp"
#include "terrain/core/version.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/release.hpp"
#include "terrain/internal/core/residency_plan.hpp"
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

bool field_splits(const SegmentOptions& options, const Input& input) {
    const auto resolved = resolve_options(options, input.dem.has_value());
    return input.dem && resolved.field == field::FieldKind::shape_index &&
           resolved.shape_index.auto_scale && input.mesh.grid_width > 0 &&
           input.mesh.vertex_pixel.size() == input.mesh.vertex_count();
}

namespace {

// Each part's first vertex, and the vertex count last: part p holds the rows [H p / parts,
// H (p + 1) / parts) of the grid, whose vertices are numbered by rows.
std::vector<std::size_t> part_bounds(const TriangleMesh& mesh, int parts) {
    std::vector<std::size_t> bounds;
    const std::int64_t width = mesh.grid_width, height = mesh.grid_height;
    for (int p = 0; p < parts; ++p) {
        const std::int64_t row = height * p / parts;
        const auto first = std::partition_point(
            mesh.vertex_pixel.begin(), mesh.vertex_pixel.end(),
            [&](std::int32_t pixel) { return std::int64_t(pixel) / width < row; });
        bounds.push_back(std::size_t(first - mesh.vertex_pixel.begin()));
    }
    bounds.push_back(mesh.vertex_count());
    return bounds;
}

}  // namespace

field::ScaleSelectedField shared_scale_selected_field(const TriangleMesh& mesh,
                                                      field::ShapeIndexOptions options,
                                                      const FieldShare& share,
                                                      const ProgressFn& progress) {
    if (share.parts <= 1) return field::scale_selected_shape_index(mesh, options, progress);
    const std::int64_t height = mesh.grid_height;
    options.first_row = int(height * share.part / share.parts);
    options.end_row = int(height * (share.part + 1) / share.parts);
    auto selected = field::scale_selected_shape_index(mesh, options, progress);
    share.gather(selected.field, selected.scale, part_bounds(mesh, share.parts));
    return selected;
}

void compute_field(SegmentResult& result, const SegmentOptions& options,
                   const ProgressFn& progress) {
    const auto t0 = clock::now();
    const auto fo = field_options(options);
    const bool split = options.field_share.parts > 1 && field_splits(options, result.input);
    if (fo.kind == field::FieldKind::shape_index && fo.shape_index.auto_scale) {
        auto selected =
            shared_scale_selected_field(result.input.mesh, fo.shape_index,
                                        split ? options.field_share : FieldShare{}, progress);
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

namespace {

// The Reeb graph of result.field, critical_before set.
reeb::ReebGraph reeb_graph(SegmentResult& result, const reeb::ReebOptions& options,
                           const ProgressFn& progress) {
    auto graph = reeb::build_reeb_graph(result.input.mesh, result.field, options, progress);
    // Only the count of critical nodes is reported: summarize() would also count the graph's
    // components and loops, a union-find over every node (about 1.5 % of a whole run).
    result.critical_before = static_cast<std::size_t>(
        std::count_if(graph.node_kinds.begin(), graph.node_kinds.end(),
                      [](reeb::NodeKind k) { return k != reeb::NodeKind::regular; }));
    report_progress(progress, 1.0, "reeb");
    return graph;
}

segment::GrowOptions grow_options(const SegmentOptions& options, bool dem) {
    segment::GrowOptions grow;
    grow.saddle_penalty = options.saddle_penalty;
    grow.cost = grow_cost(options, dem);
    return grow;
}

}  // namespace

reeb::ReebGraph compute_reeb(SegmentResult& result, const ProgressFn& progress) {
    const auto t0 = clock::now();
    auto& mesh = result.input.mesh;
    // A DEM mesh frees its triangles (24 bytes a pixel) once no stage needs them at random,
    // and the stages after make them again from the grid, in order. When the Reeb graph is a
    // tree (every component a disk or a sphere: the contour tree makes it) that is before it;
    // with loops the contour-tracking sweep walks them at random, so after.
    reeb::ReebOptions options;
    if (mesh.triangles_releasable() &&
        reeb::reeb_is_tree(mesh, scaled_progress(progress, 0, 0.1))) {
        mesh.release_triangles();
        options.known_tree = true;
    }
    auto graph = reeb_graph(result, options, scaled_progress(progress, 0.1, 1));
    mesh.release_triangles();
    result.add_time("reeb", since(t0));
    return graph;
}

namespace {

// Regions grown on a simplified graph.
ScaleResult grow_scale(const Input& input, const std::vector<float>& field,
                       const SegmentOptions& options, const reeb::SimplifyResult& simplified,
                       double simplify_seconds, const ProgressFn& progress,
                       const std::vector<std::uint32_t>* finer = nullptr) {
    ScaleResult out;
    out.after = reeb::summarize(simplified.graph);
    out.simplify_seconds = simplify_seconds;
    const auto t0 = clock::now();
    const auto grow = grow_options(options, input.dem.has_value());
    const bool divide = absorbed_mode(options, input.dem.has_value()) == Absorbed::divide;
    out.segmentation = segment::grow_regions(input.mesh, simplified.graph, grow,
                                             scaled_progress(progress, 0, divide ? 0.5 : 1));
    if (divide)
        out.divided =
            segment::divide_absorbed(input.mesh, simplified.graph, field, simplified.absorbed,
                                     out.segmentation, finer, scaled_progress(progress, 0.5, 1));
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

using detail::Held;
using detail::ResidencyPlan;

// segment()'s progress: one slice a stage, by the stages' measured cost on global grids of 1
// to 66 M pixels (docs/performance.md): the field 0.2, the Reeb graph 0.2, the simplification
// 0.2, the growing and the division 0.3, the region graph 0.1. The arrays that leave memory or
// come back on entering a stage take the first hundredths of its slice; at(slice, t) is the
// point t of the way through a slice.
struct Slice {
    double from, to;
};
constexpr Slice kFieldSlice{0, 0.2};
constexpr Slice kReebSlice{0.2, 0.4};
constexpr Slice kSimplifySlice{0.4, 0.6};
constexpr Slice kGrowSlice{0.6, 0.9};  // growing, area ranges, division
constexpr Slice kRegionsSlice{0.9, 1};
constexpr double at(const Slice& slice, double t) {
    return slice.from + t * (slice.to - slice.from);
}
ProgressFn slice_of(const ProgressFn& progress, const Slice& slice, double t0 = 0, double t1 = 1) {
    return scaled_progress(progress, at(slice, t0), at(slice, t1));
}

Stage field_stage(field::FieldKind kind) {
    switch (kind) {
        case field::FieldKind::height:
            return Stage::height_field;
        case field::FieldKind::sdf:
            return Stage::sdf;
        default:
            return Stage::shape_index;
    }
}

// The run's large arrays, bound to its memory plan (terrain/internal/core/residency_plan.hpp,
// whose stage table says which stage reads which). The DEM's values leave memory packed as
// floats when they all are floats, and parked; the mesh's triangles and positions are freed
// and made again from the grid and the DEM; the rest is parked. Whether to park is decided on
// what they hold (the field, not made yet, a float a vertex).
void bind_arrays(ResidencyPlan& plan, SegmentResult& result, PackedHeights& packed) {
    auto& mesh = result.input.mesh;
    if (result.input.dem) {
        Dem& dem = *result.input.dem;
        ResidencyPlan::Holder values;
        values.hold = [&dem, &packed](detail::ParkedArrays& store, const ProgressFn& p) {
            packed.pack(dem, scaled_progress(p, 0, 0.5));
            return packed.park(store, scaled_progress(p, 0.5, 1)) ||
                   store.park(dem.values, p, 0.5, 1) || packed.packed();
        };
        values.back = [&dem, &packed](detail::ParkedArrays& store, const ProgressFn& p) {
            store.restore(dem.values, p, 0, 0.2);
            packed.restore(store, scaled_progress(p, 0, 0.2));
            packed.unpack(dem, scaled_progress(p, 0.2, 1));
        };
        values.bytes = [&dem, &packed] { return packed.packed_bytes(dem); };
        plan.bind(Held::dem, std::move(values));
        // Placed again from the DEM: the same floats (docs/mesh.md). From its values packed as
        // floats, read back for the while and parked again, when they are (not 8 bytes a
        // pixel of doubles beside the positions made); else from the DEM brought back.
        ResidencyPlan::Holder positions;
        positions.hold = [&mesh](detail::ParkedArrays&, const ProgressFn&) {
            return mesh.release_positions();
        };
        positions.back = [&dem, &mesh, &packed](detail::ParkedArrays& store, const ProgressFn& p) {
            if (!packed.packed()) return mesh::restore_positions(dem, mesh, p);
            packed.restore(store, scaled_progress(p, 0, 0.2));
            mesh::restore_positions(dem, packed.values(), mesh, scaled_progress(p, 0.2, 0.8));
            packed.park(store, scaled_progress(p, 0.8, 1));
        };
        if (!packed.exact(dem)) positions.needs = Held::dem;
        plan.bind(Held::positions, std::move(positions));
    }
    ResidencyPlan::Holder triangles;
    triangles.hold = [&mesh](detail::ParkedArrays&, const ProgressFn&) {
        return mesh.release_triangles();
    };
    triangles.back = [&mesh](detail::ParkedArrays&, const ProgressFn&) {
        mesh.restore_triangles();
    };
    triangles.resident = !mesh.triangles_released();
    plan.bind(Held::triangles, std::move(triangles));
    const auto bytes = [](const auto& v) { return v.size() * sizeof(v[0]); };
    plan.bind(Held::vertex_areas, mesh.vertex_areas, bytes(mesh.vertex_areas));
    plan.bind(Held::pixel_vertex, mesh.pixel_vertex, bytes(mesh.pixel_vertex));
    plan.bind(Held::vertex_pixel, mesh.vertex_pixel, bytes(mesh.vertex_pixel));
    plan.bind(Held::neighbor_directions, mesh.neighbor_directions, bytes(mesh.neighbor_directions));
    plan.bind(Held::field, result.field, sizeof(float) * mesh.vertex_count());
    plan.bind(Held::field_scale, result.field_scale, 0);  // (a byte a vertex, not counted)
}

// The regions grown on the simplified graph and the absorbed vertices divided among them,
// into result.segmentation; once the graph is read no more, the regions' range of area
// thresholds (simplifying it on, and consuming it) into `ranges`. kGrowSlice. Returns the
// seconds the ranges took.
double grow_regions(SegmentResult& result, const SegmentOptions& options,
                    const reeb::SimplifyOptions& thresholds, reeb::SimplifyResult& simplified,
                    ResidencyPlan& plan, std::vector<double>& ranges, const ProgressFn& progress) {
    auto& mesh = result.input.mesh;
    const bool dem = result.input.dem.has_value();
    const bool divide = absorbed_mode(options, dem) == Absorbed::divide;
    result.after = reeb::summarize(simplified.graph);
    plan.enter(Stage::grow, slice_of(progress, kGrowSlice, 0, 0.07));
    result.segmentation = segment::grow_regions(mesh, simplified.graph, grow_options(options, dem),
                                                slice_of(progress, kGrowSlice, 0.07, 0.5));
    plan.bind(Held::labels, result.segmentation.labels, 0);
    double seconds = 0;
    plan.on_entry(Stage::flood, [&](const ProgressFn& slice) {
        detail::release(simplified.absorbed);
        const auto t0 = clock::now();
        if (options.min_area.is_auto()) {
            segment::AreaRangeOptions range;
            range.floor_m2 = result.min_area_m2;
            range.persistence = thresholds.persistence;
            ranges = segment::seed_area_ranges(mesh, std::move(simplified.graph),
                                               result.segmentation.seeds, range, slice);
        }
        simplified.graph = reeb::ReebGraph{};
        seconds = since(t0);
    });
    if (divide) {
        result.divided = segment::divide_absorbed(mesh, simplified.graph, result.field,
                                                  simplified.absorbed, result.segmentation, nullptr,
                                                  slice_of(progress, kGrowSlice, 0.5, 1), plan);
    } else {
        plan.enter(Stage::flood, slice_of(progress, kGrowSlice, 0.5, 1));
        plan.enter(Stage::relabel);
    }
    return seconds;
}

// The region graph, its scales and area ranges, the craters. kRegionsSlice.
void make_regions(SegmentResult& result, const SegmentOptions& options,
                  const std::vector<double>& ranges, ResidencyPlan& plan,
                  const ProgressFn& progress) {
    plan.enter(Stage::regions, slice_of(progress, kRegionsSlice, 0, 0.05));
    result.regions = segment::region_graph(
        result.input.mesh, result.field, result.segmentation.labels,
        result.segmentation.region_count, result.dem(), slice_of(progress, kRegionsSlice, 0.05, 1));
    // On a DEM, with the regions of valid pixels in no triangle (segment::label_pixels).
    result.segmentation.region_count = static_cast<std::uint32_t>(result.regions.regions.size());
    internal::set_region_scales(result);
    if (options.min_area.is_auto()) internal::set_area_ranges(result, ranges);
    if (options.craters && result.input.dem)
        result.craters = segment::find_craters(result.input.mesh, *result.input.dem,
                                               result.segmentation.labels, result.regions);
}

}  // namespace

// The stages in turn, each in its slice of the progress, the memory plan moving the arrays
// each does not read out of memory and those it reads back.
SegmentResult segment(Input input, const SegmentOptions& requested, const ProgressFn& progress) {
    check_options(requested);
    const SegmentOptions options = resolve_options(requested, input.dem.has_value());
    // A polygon format that cannot hold the DEM's coordinates is refused before any work.
    if (input.dem) io::check_polygon_format(*input.dem, options.format);
    SegmentResult result;
    result.input = std::move(input);
    result.timings.push_back({"read", result.input.read_seconds});
    if (result.input.dem) result.timings.push_back({"mesh", result.input.mesh_seconds});
    auto& mesh = result.input.mesh;
    PackedHeights packed;
    ResidencyPlan plan(options.park_directory, options.park_min_bytes);
    bind_arrays(plan, result, packed);

    auto t0 = clock::now();
    const Stage field = field_stage(options.field);
    plan.enter(field, slice_of(progress, kFieldSlice, 0, 0.05));
    result.parked_field = plan.parked_in(field);
    result.add_time("field", since(t0));
    compute_field(result, options, slice_of(progress, kFieldSlice, 0.05, 1));
    if (options.field_share.stop_after_field) return result;

    t0 = clock::now();
    plan.enter(Stage::reeb_events, slice_of(progress, kReebSlice, 0, 0.05));
    reeb::ReebOptions reeb_options;
    reeb_options.memory = &plan;
    auto graph = reeb_graph(result, reeb_options, slice_of(progress, kReebSlice, 0.05, 1));
    result.add_time("reeb", since(t0));

    t0 = clock::now();
    plan.enter(Stage::simplify_nodes, slice_of(progress, kSimplifySlice, 0, 0.05));
    const auto thresholds = simplify_options(options, mesh);
    result.area_ratio_percent = thresholds.area_ratio;
    result.min_area_m2 = min_area_m2(options, mesh);
    auto simplified = reeb::simplify(mesh, std::move(graph), thresholds,
                                     slice_of(progress, kSimplifySlice, 0.05, 1), plan);
    result.parked_bytes = plan.parked_in(Stage::simplify_arcs);
    const double simplify_seconds = since(t0);

    t0 = clock::now();
    std::vector<double> ranges;
    const double range_seconds =
        grow_regions(result, options, thresholds, simplified, plan, ranges, progress);
    result.parked_growing = plan.parked_in(Stage::flood);
    simplified = reeb::SimplifyResult{};
    make_regions(result, options, ranges, plan, progress);
    // (The ranges simplify the graph on: counted with the simplification.)
    result.add_time("simplify", simplify_seconds + range_seconds);
    result.add_time("grow", since(t0) - range_seconds);
    result.parked_file = plan.store().file_peak();
    result.parked_most = plan.store().most_parked();
    return result;
}

}  // namespace terrain::pipeline
