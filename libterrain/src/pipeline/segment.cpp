#include "terrain/pipeline/segment.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <type_traits>

#include "../core/pass_progress.hpp"
#include "../core/release.hpp"
#include "../core/significant.hpp"
#include "parked_arrays.hpp"
#include "region_scales.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/huge_pages.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/core/memory_budget.hpp"
#include "terrain/core/version.hpp"
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

namespace {

using clock = std::chrono::steady_clock;
double since(clock::time_point t0) {
    return std::chrono::duration<double>(clock::now() - t0).count();
}

}  // namespace

std::optional<MeshFrame> parse_frame(const std::string& name) {
    if (name == "body") return MeshFrame::body;
    if (name == "map") return MeshFrame::map;
    if (name == "auto") return std::nullopt;
    throw Error("mesh", "the frame must be body, map or auto, not '" + name + "'");
}

Input load_input(const std::string& path, const InputOptions& options, const ProgressFn& progress) {
    const auto t0 = clock::now();
    const MemoryPlan plan =
        memory_plan(options.planned_field, options.max_memory, options.planned_segment);
    if (io::is_mesh_file(path)) {
        io::ReadMeshOptions read_options;
        read_options.repair = options.repair;
        Input input;
        input.mesh = io::read_mesh(path, read_options, progress, plan);
        input.read_seconds = since(t0);
        return input;
    }
    const auto frame = parse_frame(options.frame);
    io::ReadDemOptions dem_options = options.dem;
    dem_options.memory = plan;
    Dem dem = io::read_dem(path, dem_options, scaled_progress(progress, 0, 0.3));
    const double read_seconds = since(t0);
    mesh::DemToMeshOptions mesh_options;
    mesh_options.frame = frame;
    // pipeline::segment frees the triangles of a tree before the field (below): they may go
    // before the mesh's areas and adjacency, unless the SDF is to cast rays through them.
    mesh_options.release_triangles = options.planned_segment && options.planned_field != "sdf";
    const auto t1 = clock::now();
    Input input;
    input.mesh = mesh::dem_to_mesh(dem, mesh_options, scaled_progress(progress, 0.3, 1));
    input.mesh_seconds = since(t1);
    input.read_seconds = read_seconds;
    input.dem = std::move(dem);
    return input;
}

Input input_from_dem(Dem dem, const std::string& frame, const ProgressFn& progress) {
    mesh::DemToMeshOptions mesh_options;
    mesh_options.frame = parse_frame(frame);
    const auto t0 = clock::now();
    Input input;
    input.mesh = mesh::dem_to_mesh(dem, mesh_options, progress);
    input.mesh_seconds = since(t0);
    input.dem = std::move(dem);
    return input;
}

void check_options(const SegmentOptions& o) {
    field::parse_field_kind(o.field);
    if (!std::isfinite(o.simplify.persistence) || o.simplify.persistence < 0)
        throw Error("segment", "--persistence must be a number >= 0");
    if (!std::isfinite(o.simplify.area_ratio) || o.simplify.area_ratio < 0 ||
        o.simplify.area_ratio > 100)
        throw Error("segment", "--area-ratio is a percentage of the surface: between 0 and 100");
    if (!std::isfinite(o.saddle_penalty) || o.saddle_penalty < 0)
        throw Error("segment", "--saddle-penalty must be a number >= 0");
    if (o.cost != "auto") segment::parse_grow_cost(o.cost);
    if (!o.min_area.empty() && o.min_area != "auto") parse_area(o.min_area);
    parse_absorbed(o.absorbed);
}

Absorbed parse_absorbed(const std::string& name, bool dem) {
    if (name == "divide") return Absorbed::divide;
    if (name == "whole") return Absorbed::whole;
    if (name == "auto") return dem ? Absorbed::divide : Absorbed::whole;
    throw Error("segment", "--absorbed is divide, whole or auto; '" + name + "' is none of them");
}

SegmentOptions resolve_options(const SegmentOptions& options, bool dem) {
    SegmentOptions out = options;
    if (out.absorbed == "auto") out.absorbed = dem ? "divide" : "whole";
    if (out.landform_defaults && dem && out.field == "shape-index") {
        out.shape_index.auto_scale = true;
        out.min_area = "auto";
    }
    out.landform_defaults = false;
    return out;
}

double min_area_m2(const SegmentOptions& options, const TriangleMesh& mesh) {
    if (options.min_area.empty()) return 0;
    if (options.min_area != "auto") return parse_area(options.min_area);
    const double pixel = mean_vertex_area(mesh);
    if (!(pixel > 0) || !std::isfinite(pixel))
        throw Error("segment", "--min-area auto needs a mesh with a positive area");
    return kAutoMinAreaPixels * pixel;
}

double parse_area(const std::string& text, const std::string& option) {
    std::size_t used = 0;
    double value = 0;
    try {
        value = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    std::string unit = used > 0 ? text.substr(used) : std::string();
    unit.erase(0, unit.find_first_not_of(' '));
    std::transform(unit.begin(), unit.end(), unit.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    double scale = 0;
    if (unit.empty() || unit == "m2" || unit == "m^2")
        scale = 1;
    else if (unit == "km2" || unit == "km^2")
        scale = 1e6;
    else if (unit == "ha")
        scale = 1e4;
    const double m2 = value * scale;
    if (used == 0 || scale == 0 || !std::isfinite(m2) || m2 <= 0)
        throw Error("segment", option +
                                   " takes an area above 0 in m^2 or with a unit (5km2, "
                                   "2000m2, 3ha); '" +
                                   text + "' is not one");
    return m2;
}

reeb::SimplifyOptions simplify_options(const SegmentOptions& options, const TriangleMesh& mesh) {
    reeb::SimplifyOptions out = options.simplify;
    out.rewrite_field = false;  // (the regions grow on the graph and the field as computed)
    if (!options.min_area.empty())
        out.area_ratio = reeb::area_ratio_for_area(mesh, min_area_m2(options, mesh));
    return out;
}

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

field::FieldOptions field_options(const SegmentOptions& o) {
    field::FieldOptions out;
    out.kind = field::parse_field_kind(o.field);
    out.shape_index = o.shape_index;
    out.sdf.rays = o.rays;
    out.sdf.cone_angle = o.cone_angle_degrees * std::numbers::pi / 180.0;
    out.sdf.postprocess = o.postprocess;
    out.sdf.allow_open = o.allow_open;
    return out;
}

segment::GrowCost grow_cost(const SegmentOptions& o, bool dem) {
    if (o.cost == "auto") return dem ? segment::GrowCost::graph : segment::GrowCost::standard;
    return segment::parse_grow_cost(o.cost);
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
    if (options.field == "shape-index") {
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

// Regions grown on a simplified graph.
ScaleResult grow_scale(const Input& input, const std::vector<float>& field,
                       const SegmentOptions& options, const reeb::SimplifyResult& simplified,
                       double simplify_seconds, const ProgressFn& progress,
                       const std::vector<std::uint32_t>* finer = nullptr) {
    ScaleResult out;
    out.after = reeb::summarize(simplified.graph);
    out.simplify_seconds = simplify_seconds;
    const auto t0 = clock::now();
    segment::GrowOptions grow;
    grow.saddle_penalty = options.saddle_penalty;
    grow.cost = grow_cost(options, input.dem.has_value());
    const bool divide = parse_absorbed(options.absorbed, input.dem.has_value()) == Absorbed::divide;
    out.segmentation = segment::grow_regions(input.mesh, simplified.graph, grow,
                                             scaled_progress(progress, 0, divide ? 0.5 : 1));
    if (divide)
        out.divided =
            segment::divide_absorbed(input.mesh, simplified.graph, field, simplified.absorbed,
                                     out.segmentation, finer, scaled_progress(progress, 0.5, 1));
    out.grow_seconds = since(t0);
    return out;
}

// The DEM's values held as floats while the stages that do not read them run, when every
// value is one exactly (16- and 32-bit samples, and integers times a power of two below 2^24
// of them): 4 bytes a pixel less. They are doubles again, the same numbers, where they are
// read (the placing of the positions, the region graph's points); a DEM with a value no float
// holds keeps its doubles. Packed again later, the values are not checked again.
class PackedHeights {
  public:
    void pack(Dem& dem, const ProgressFn& progress) {
        const std::size_t n = dem.values.size();
        const detail::PassProgress checked(progress, 0, 0.4, "mesh"),
            packed(progress, 0.4, 1, "mesh");
        if (!exact_) {
            for (std::size_t i = 0; i < n; ++i) {
                checked.at(i, n);
                const double v = dem.values[i];
                if (!std::isnan(v) && static_cast<double>(static_cast<float>(v)) != v) return;
            }
            exact_ = true;
        }
        values_.reserve(n);
        for (std::size_t i = 0; i < n; ++i) {
            packed.at(i, n);
            values_.push_back(static_cast<float>(dem.values[i]));
        }
        detail::release(dem.values);
        packed_ = true;
    }
    // The bytes of the DEM's values as held now.
    std::size_t bytes(const Dem& dem) const {
        return packed_ ? values_.size() * sizeof(float) : dem.values.size() * sizeof(double);
    }
    // The floats parked (parked_arrays.hpp) and read back.
    bool park(internal::ParkedArrays& parked, const ProgressFn& progress) {
        return packed_ && parked.park(values_, progress, 0, 1);
    }
    void restore(internal::ParkedArrays& parked, const ProgressFn& progress) {
        if (packed_) parked.restore(values_, progress, 0, 1);
    }
    void unpack(Dem& dem, const ProgressFn& progress) {
        if (!packed_) return;
        const std::size_t n = values_.size();
        const detail::PassProgress unpacked(progress, 0, 1, "mesh");
        dem.values.reserve(n);
        for (std::size_t i = 0; i < n; ++i) {
            unpacked.at(i, n);
            dem.values.push_back(static_cast<double>(values_[i]));
        }
        detail::release(values_);
        packed_ = false;
    }

  private:
    std::vector<float> values_;
    bool packed_ = false;
    bool exact_ = false;  // every value is a float
};

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

SegmentResult segment(Input input, const SegmentOptions& requested, const ProgressFn& progress) {
    check_options(requested);
    const SegmentOptions options = resolve_options(requested, input.dem.has_value());
    // A polygon format that cannot hold the DEM's coordinates is refused before any work.
    if (input.dem) io::check_polygon_format(*input.dem, options.format);
    SegmentResult result;
    result.input = std::move(input);
    result.timings.push_back({"read", result.input.read_seconds});
    if (result.input.dem) result.timings.push_back({"mesh", result.input.mesh_seconds});
    // Slices of the progress by the stages' measured cost on global grids of 1 to 66 M
    // pixels (docs/performance.md): field 0.2, Reeb graph 0.2, simplification 0.2, growing
    // and dividing 0.3, region graph 0.1.
    // A DEM mesh whose Reeb graph is a tree (every component a disk or a sphere) frees its
    // triangles (24 bytes a pixel) before the field: no stage reads them at random, the
    // shape index's normals and the later stages walk them again from the grid in order.
    // The SDF casts rays through them: it keeps them. (The loop check is counted with the
    // field, which it precedes.)
    auto& mesh = result.input.mesh;
    const auto tf = clock::now();
    const auto kind = field::parse_field_kind(options.field);
    const bool tree = kind != field::FieldKind::sdf &&
                      (mesh.triangles_released() || mesh.triangles_releasable()) &&
                      reeb::reeb_is_tree(mesh, scaled_progress(progress, 0, 0.02));
    if (tree)
        mesh.release_triangles();
    else
        mesh.restore_triangles();  // (released by load_input: the Reeb graph reads them)
    result.add_time("field", since(tf));
    // The DEM's values (as floats when they all are floats), then the field and the mesh's
    // pixel maps, wait unread through the stages that do not read them: parked on disk
    // (parked_arrays.hpp; docs/performance.md, "Arrays parked on disk") when large. The DEM
    // waits from before the field (only the height field reads it) to the placing of the
    // positions, and again through the growing.
    // Whether to park at all is decided the first time, on what all the arrays parked through
    // the run hold (the field is a float a vertex).
    PackedHeights packed;
    internal::ParkedArrays parked(options.park_directory, options.park_min_bytes);
    const auto hold_dem = [&](const ProgressFn& held) {
        Dem& dem = *result.input.dem;
        packed.pack(dem, scaled_progress(held, 0, 0.5));
        if (!parked.decided())
            parked.decide(packed.bytes(dem) +
                          sizeof(float) * (mesh.vertex_count() + mesh.vertex_areas.size()) +
                          sizeof(std::int32_t) *
                              (mesh.pixel_vertex.size() + mesh.vertex_pixel.size()) +
                          mesh.neighbor_directions.size());
        if (!packed.park(parked, scaled_progress(held, 0.5, 1)))
            parked.park(dem.values, held, 0.5, 1);
    };
    const bool field_reads_dem = kind == field::FieldKind::height;
    if (result.input.dem && !field_reads_dem) hold_dem(scaled_progress(progress, 0.02, 0.03));
    result.parked_field = parked.parked_bytes();
    compute_field(
        result, options,
        scaled_progress(progress, field_reads_dem ? 0.02 : 0.03, field_reads_dem ? 0.19 : 0.2));
    // A DEM mesh frees its positions (12 bytes a vertex) while the Reeb graph and the
    // simplification run, which do not read them, and places them again before the growing:
    // the same floats (docs/mesh.md, "Positions freed and placed again").
    const bool placed_again = result.input.dem && mesh.release_positions();
    const auto tp = clock::now();
    if (result.input.dem) {
        if (field_reads_dem) hold_dem(scaled_progress(progress, 0.19, 0.2));
        // The vertices' areas wait through the Reeb graph, which does not read them (the
        // simplification does).
        parked.park(mesh.vertex_areas, progress, 0.2, 0.21);
    }
    result.add_time("reeb", since(tp));  // (which it precedes: the times stay in run order)
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
        result, scaled_progress(progress, 0.21, 0.4), tree,
        [&] { parked.park(result.field, {}, 0, 0); }, sweeps);
    const auto ta = clock::now();
    parked.restore(mesh.vertex_areas, progress, 0.4, 0.4);
    result.add_time("reeb", since(ta));
    // One scale only: the simplification takes the graph and frees what it no longer needs,
    // which lowers the peak memory.
    const auto t0 = clock::now();
    if (parked.on()) {
        if (!result.field.empty()) parked.park(result.field, progress, 0.4, 0.403);
        parked.park(mesh.pixel_vertex, progress, 0.403, 0.406);
        parked.park(mesh.vertex_pixel, progress, 0.406, 0.409);
        parked.park(mesh.neighbor_directions, progress, 0.409, 0.41);
    }
    result.parked_bytes = parked.parked_bytes();
    const auto thresholds = simplify_options(options, result.input.mesh);
    result.area_ratio_percent = thresholds.area_ratio;
    result.min_area_m2 = min_area_m2(options, result.input.mesh);
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
        result.input.mesh, std::move(graph), thresholds, scaled_progress(progress, 0.41, 0.6),
        [&] {
            if (parked.park(mesh.vertex_areas, {}, 0, 0))
                result.parked_bytes = parked.parked_bytes();
        },
        vertex_nodes);
    const double seconds = since(t0);
    // (Counted with the growing, which it precedes: the stages' times stay in run order.)
    const auto t2 = clock::now();
    parked.restore(mesh.vertex_areas, progress, 0.6, 0.6);
    parked.restore(mesh.neighbor_directions, progress, 0.6, 0.601);
    parked.restore(mesh.vertex_pixel, progress, 0.601, 0.602);
    parked.restore(mesh.pixel_vertex, progress, 0.602, 0.603);
    parked.restore(result.field, progress, 0.603, 0.604);
    // The DEM back as doubles for the placing of the positions, then waiting again through
    // the growing, which does not read it; back for the region graph's points.
    const auto restore_dem = [&](const ProgressFn& back) {
        parked.restore(result.input.dem->values, back, 0, 0.2);
        packed.restore(parked, scaled_progress(back, 0, 0.2));
        packed.unpack(*result.input.dem, scaled_progress(back, 0.2, 1));
    };
    if (result.input.dem) restore_dem(scaled_progress(progress, 0.604, 0.61));
    if (placed_again)
        mesh::restore_positions(*result.input.dem, mesh, scaled_progress(progress, 0.61, 0.615));
    if (result.input.dem && parked.on()) hold_dem(scaled_progress(progress, 0.615, 0.62));
    result.parked_growing = parked.parked_bytes();
    const double placing = since(t2);
    auto scale = grow_scale(result.input, result.field, options, simplified, seconds,
                            scaled_progress(progress, 0.62, 0.86));
    result.segmentation = std::move(scale.segmentation);
    result.after = scale.after;
    result.divided = scale.divided;
    // The regions' range of area thresholds, simplifying the graph on (counted with the
    // simplification): the graph goes as it is read.
    std::vector<double> ranges;
    if (options.min_area == "auto") {
        const auto tr = clock::now();
        segment::AreaRangeOptions range;
        range.floor_m2 = result.min_area_m2;
        range.persistence = thresholds.persistence;
        ranges =
            segment::seed_area_ranges(mesh, std::move(simplified.graph), result.segmentation.seeds,
                                      range, scaled_progress(progress, 0.86, 0.9));
        scale.simplify_seconds += since(tr);
    }
    result.add_time("simplify", scale.simplify_seconds);
    // The simplified graph, its rewritten field and its absorbed flags are read no more: they
    // go before the DEM comes back as doubles for the region graph (the growing's peak).
    simplified = reeb::SimplifyResult{};
    const auto t1 = clock::now();
    if (result.input.dem) restore_dem(scaled_progress(progress, 0.9, 0.905));
    result.regions = segment::region_graph(
        result.input.mesh, result.field, result.segmentation.labels,
        result.segmentation.region_count, result.dem(), scaled_progress(progress, 0.905, 1));
    // On a DEM, with the regions of valid pixels in no triangle (segment::label_pixels).
    result.segmentation.region_count = static_cast<std::uint32_t>(result.regions.regions.size());
    internal::set_region_scales(result);
    if (options.min_area == "auto") internal::set_area_ranges(result, ranges);
    if (options.craters && result.input.dem)
        result.craters = segment::find_craters(mesh, *result.input.dem, result.segmentation.labels,
                                               result.regions);
    result.add_time("grow", placing + scale.grow_seconds + since(t1));
    result.parked_file = parked.file_peak();
    result.parked_most = parked.most_parked();
    return result;
}

// A DEM mesh's geometry, which its files do not read (the counts for run.json kept first).
static void release_mesh_geometry(SegmentResult& result) {
    if (!result.mesh_counts) result.mesh_counts = mesh_counts(result.input.mesh);
    auto& m = result.input.mesh;
    m.release_positions();  // (the vertex count stays; a mesh that cannot keeps them)
    m.release_triangles();
    detail::release(m.vertex_areas);
    m.release_adjacency();
    release_free_memory();
}

void release_large_data(SegmentResult& result) {
    if (!result.mesh_counts) result.mesh_counts = mesh_counts(result.input.mesh);
    // (`v = {}` would keep a vector's capacity: it is the initializer-list assignment.)
    auto drop = [](auto& v) { std::decay_t<decltype(v)>().swap(v); };
    auto& m = result.input.mesh;
    drop(m.positions);
    drop(m.triangles);
    drop(m.vertex_areas);
    m.release_adjacency();
    drop(m.pixel_vertex);
    drop(m.vertex_pixel);
    drop(result.field);
    drop(result.segmentation.labels);
    drop(result.segmentation.seeds);
    release_free_memory();
}

// A length and an area for the preview's caption, in m or km, three significant digits.
std::string caption_length(double m) {
    return m >= 1000 ? terrain::detail::significant(m / 1000, 3) + " km"
                     : terrain::detail::significant(m, 3) + " m";
}
std::string caption_area(double m2) {
    return m2 >= 1e5 ? terrain::detail::significant(m2 / 1e6, 3) + " km^2"
                     : terrain::detail::significant(m2, 3) + " m^2";
}

// The preview's words for a scale chosen per vertex: the ladder's ends.
std::string scale_caption(const std::vector<double>& radii) {
    if (radii.empty()) return "radius auto";
    return "radius auto (" + std::to_string(radii.size()) + " radii, " +
           caption_length(radii.front()) + " to " + caption_length(radii.back()) + ")";
}

std::vector<std::string> write_segment_directory(SegmentResult& result, const SegmentOptions& given,
                                                 const std::string& input_path,
                                                 const std::string& dir, const WriteOptions& write,
                                                 const ProgressFn& progress) {
    const SegmentOptions options = resolve_options(given, result.input.dem.has_value());
    const auto t0 = clock::now();
    release_free_memory();  // (freed blocks a program keeps: GDAL's block cache comes next)
    io::SegmentOutputOptions out;
    out.polygons.driver = options.format;
    out.preview_caption.input = fs::path(input_path).filename().string();
    out.preview_caption.field = options.field;
    auto& caption = out.preview_caption.parameters;
    if (options.field == "shape-index" && options.shape_index.auto_scale)
        caption.push_back(scale_caption(result.field_radii));
    else if (options.field == "shape-index")
        caption.push_back(
            options.shape_index.radius > 0
                ? "radius " + JsonWriter::number(options.shape_index.radius) + " m (" +
                      field::shape_index_window(result.input.mesh, options.shape_index) + ")"
                : std::to_string(options.shape_index.rings) + " rings");
    caption.push_back("persistence " + JsonWriter::number(options.simplify.persistence));
    if (options.min_area == "auto")
        caption.push_back("min area auto (" + caption_area(result.min_area_m2) + ")");
    else
        caption.push_back(
            "area ratio " + JsonWriter::number(result.area_ratio_percent) + " %" +
            (options.min_area.empty() ? std::string() : " (min area " + options.min_area + ")"));
    caption.push_back("cost " +
                      std::string(options.cost == "auto" ? (result.input.dem ? "graph" : "standard")
                                                         : options.cost) +
                      ", saddle penalty " + JsonWriter::number(options.saddle_penalty));
    caption.push_back("absorbed " + options.absorbed);
    // The preview is written last, once the large data is freed.
    io::PreviewImage preview;
    const bool deferred = write.release_memory && result.input.dem;
    // The files of a DEM read the labels, the field and the pixel maps, not the mesh's
    // positions, areas, triangles or adjacency (about 17 bytes a pixel): they go first.
    if (deferred) {
        release_mesh_geometry(result);
        out.deferred_preview = &preview;
    }
    const auto paths =
        io::write_segment_outputs(dir, result.input.mesh, result.field, result.segmentation.labels,
                                  result.regions, result.dem(), out, progress);
    std::vector<std::string> names;
    for (const auto& p : paths) {
        names.push_back(fs::path(p).filename().string());
        // The QGIS style written with the label raster.
        if (result.dem() && p == paths.front())
            names.push_back(fs::path(io::label_style_path(p)).filename().string());
    }
    if (result.craters) {
        io::write_craters_csv(*result.craters, (fs::path(dir) / "craters.csv").string(), false);
        io::write_craters_geojson(*result.craters, (fs::path(dir) / "craters.geojson").string(),
                                  false);
        names.push_back("craters.csv");
        names.push_back("craters.geojson");
        const auto gpkg = fs::path(dir) / "regions.gpkg";
        if (options.format == "GPKG" && fs::exists(gpkg))
            io::add_crater_layers(*result.craters, gpkg.string());
        double area = 0;
        for (const auto& r : result.regions.regions) area += r.area_m2;
        if (area > 0) {
            io::write_craters_plot(*result.craters, area, (fs::path(dir) / "craters.png").string(),
                                   false);
            names.push_back("craters.png");
        }
        if (result.craters->lonlat) {
            io::write_craters_scc(*result.craters, result.dem()->body, area,
                                  (fs::path(dir) / "craters.scc").string(), false);
            names.push_back("craters.scc");
        }
    }
    result.add_time("write", since(t0));
    if (write.release_memory) release_large_data(result);
    if (deferred) {
        const auto t1 = clock::now();
        io::write_preview_image(preview, (fs::path(dir) / "preview.png").string(), false);
        result.add_time("write", since(t1));
    }
    write_run_json(result, input_path, options, names, (fs::path(dir) / "run.json").string());
    names.push_back("run.json");
    return names;
}

void write_run_json(const SegmentResult& result, const std::string& input_path,
                    const SegmentOptions& given, const std::vector<std::string>& files,
                    const std::string& path,
                    const std::vector<std::pair<std::string, std::string>>& extra) {
    const SegmentOptions options = resolve_options(given, result.input.dem.has_value());
    std::ofstream os(path, std::ios::binary);
    if (!os) throw Error("write", "cannot write " + path);
    JsonWriter j(os);
    const auto topo = result.mesh_counts ? *result.mesh_counts : mesh_counts(result.input.mesh);
    const auto& after = result.after;
    const bool dem = result.input.dem.has_value();
    j.begin_object();
    j.field("input", fs::absolute(input_path).lexically_normal().string());
    j.key("parameters")
        .begin_object()
        .field("field", options.field)
        .field("rings", options.shape_index.rings);
    if (options.shape_index.auto_scale) {
        j.field("radius", "auto").key("radii_m").begin_array();
        for (const double r : result.field_radii) j.value(r);
        j.end_array()
            .field("contrast_curvedness", options.shape_index.contrast_curvedness)
            .field("pixel_noise_m", result.pixel_noise_m);
    } else {
        j.field("radius", options.shape_index.radius);
    }
    j.field("persistence", options.simplify.persistence)
        .field("area_ratio_percent",
               options.min_area.empty() ? options.simplify.area_ratio : result.area_ratio_percent);
    if (!options.min_area.empty())
        j.field("min_area", options.min_area).field("min_area_m2", result.min_area_m2);
    if (result.regions.has_area_range) internal::write_area_range(j, result);
    j.field("cost", options.cost == "auto" ? (dem ? "graph" : "standard") : options.cost.c_str())
        .field("saddle_penalty", options.saddle_penalty)
        .field("absorbed", options.absorbed)
        .field("format", options.format)
        .field("frame", to_string(result.input.mesh.frame));
    if (options.field == "shape-index") {
        const auto& mesh = result.input.mesh;
        j.field("shape_index_method",
                !result.shape_index_method.empty()
                    ? result.shape_index_method
                    : std::string(field::shape_index_method(mesh, options.shape_index)))
            .field("shape_index_window",
                   !result.shape_index_window.empty()
                       ? result.shape_index_window
                       : std::string(field::shape_index_window(mesh, options.shape_index)));
    }
    if (options.field == "sdf")
        j.field("rays", options.rays)
            .field("cone_angle_degrees", options.cone_angle_degrees)
            .field("postprocess", options.postprocess)
            .field("allow_open", options.allow_open);
    j.end_object();
    j.key("counts")
        .begin_object()
        .field("vertices", topo.vertices)
        .field("faces", topo.faces)
        .field("boundary_edges", topo.boundary_edges)
        .field("euler_characteristic", topo.euler_characteristic)
        .field("critical_nodes_before", result.critical_before)
        .field("critical_nodes_after", after.critical)
        .field("loops", after.loops)
        .field("regions", static_cast<std::size_t>(result.segmentation.region_count))
        .field("relaxed_nodes", result.segmentation.relaxed_nodes)
        .field("absorbed_vertices", result.divided.absorbed)
        .field("absorbed_relabelled", result.divided.relabelled)
        .field("parked_bytes", result.parked_bytes)
        .field("parked_bytes_field", result.parked_field)
        .field("parked_bytes_growing", result.parked_growing)
        .field("parked_bytes_most", result.parked_most)
        .field("parked_file_bytes", result.parked_file);
    if (result.craters) j.field("craters", result.craters->craters.size());
    j.end_object();
    j.key("timings_seconds").begin_object();
    double total = 0;
    for (const auto& t : result.timings) {
        j.field(t.name, t.seconds);
        total += t.seconds;
    }
    j.field("total", total).end_object();
    j.key("outputs").begin_array();
    for (const auto& f : files) j.value(f);
    j.end_array();
    for (const auto& [k, v] : extra) j.key(k).raw(v);
    j.field("pages", huge_page_use());  // huge or normal pages for the arrays (speed only)
    j.key("versions").begin_object().field("terrain", version());
    for (const auto& [name, v] : dependency_versions()) j.field(name, v);
    j.end_object();
    j.end_object();
    os.flush();
    if (!os) throw Error("write", "writing " + path + " failed (disk full?)");
}

SegmentResult segment_to_directory(const std::string& input_path, const std::string& output_dir,
                                   bool overwrite, const InputOptions& input_options,
                                   const SegmentOptions& options, const ProgressFn& progress) {
    check_options(options);
    OutputDirectory dir(output_dir, overwrite);
    InputOptions planned = input_options;
    planned.planned_field = options.field;  // the plan of the field segmented
    planned.planned_segment = true;
    auto input = load_input(input_path, planned, scaled_progress(progress, 0, 0.15));
    auto result = segment(std::move(input), options, scaled_progress(progress, 0.15, 0.7));
    WriteOptions write;
    write.release_memory = true;
    write_segment_directory(result, options, input_path, dir.temp_path(), write,
                            scaled_progress(progress, 0.7, 0.95));
    dir.commit();
    report_progress(progress, 1.0);
    return result;
}

}  // namespace terrain::pipeline
