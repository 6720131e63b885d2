// The segment job's output directory: its files written (io::write_segment_outputs, the
// crater files, the preview last), run.json, and the large data freed before them.
#include <filesystem>
#include <fstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "region_scales.hpp"
#include "stage_clock.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/huge_pages.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/core/version.hpp"
#include "terrain/internal/core/release.hpp"
#include "terrain/internal/core/significant.hpp"
#include "terrain/io/dependency_versions.hpp"
#include "terrain/io/write_craters.hpp"
#include "terrain/io/write_label_raster.hpp"
#include "terrain/io/write_preview.hpp"
#include "terrain/io/write_segment_outputs.hpp"
#include "terrain/pipeline/segment.hpp"

namespace terrain::pipeline {

namespace fs = std::filesystem;
using internal::clock;
using internal::since;

namespace {

// A DEM mesh's geometry, which its files do not read (the counts for run.json kept first).
void release_mesh_geometry(SegmentResult& result) {
    if (!result.mesh_counts) result.mesh_counts = mesh_counts(result.input.mesh);
    auto& m = result.input.mesh;
    m.release_positions();  // (the vertex count stays; a mesh that cannot keeps them)
    m.release_triangles();
    detail::release(m.vertex_areas);
    m.release_adjacency();
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

}  // namespace

void release_large_data(SegmentResult& result) {
    if (!result.mesh_counts) result.mesh_counts = mesh_counts(result.input.mesh);
    // (`v = {}` would keep a vector's capacity: it is the initializer-list assignment.)
    auto drop = [](auto& v) { std::decay_t<decltype(v)>().swap(v); };
    auto& m = result.input.mesh;
    m.drop_geometry();
    drop(m.vertex_areas);
    m.release_adjacency();
    drop(m.pixel_vertex);
    drop(m.vertex_pixel);
    drop(result.field);
    drop(result.segmentation.labels);
    drop(result.segmentation.seeds);
    release_free_memory();
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
    const bool shape_index = options.field == field::FieldKind::shape_index;
    if (shape_index && options.shape_index.auto_scale)
        caption.push_back(scale_caption(result.field_radii));
    else if (shape_index)
        caption.push_back(
            options.shape_index.radius > 0
                ? "radius " + JsonWriter::number(options.shape_index.radius) + " m (" +
                      field::shape_index_window(result.input.mesh, options.shape_index) + ")"
                : std::to_string(options.shape_index.rings) + " rings");
    caption.push_back("persistence " + JsonWriter::number(options.simplify.persistence));
    if (options.min_area.is_auto())
        caption.push_back("min area auto (" + caption_area(result.min_area_m2) + ")");
    else
        caption.push_back("area ratio " + JsonWriter::number(result.area_ratio_percent) + " %" +
                          (options.min_area.is_set()
                               ? " (min area " + to_string(options.min_area) + ")"
                               : std::string()));
    const bool dem = result.input.dem.has_value();
    caption.push_back("cost " + std::string(segment::to_string(grow_cost(options, dem))) +
                      ", saddle penalty " + JsonWriter::number(options.saddle_penalty));
    caption.push_back("absorbed " + std::string(to_string(absorbed_mode(options, dem))));
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
        .field("field", field::to_string(options.field))
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
               options.min_area.is_set() ? result.area_ratio_percent : options.simplify.area_ratio);
    if (options.min_area.is_set())
        j.field("min_area", to_string(options.min_area)).field("min_area_m2", result.min_area_m2);
    if (result.regions.has_area_range) internal::write_area_range(j, result);
    j.field("cost", segment::to_string(grow_cost(options, dem)))
        .field("saddle_penalty", options.saddle_penalty)
        .field("absorbed", to_string(absorbed_mode(options, dem)))
        .field("format", options.format)
        .field("frame", to_string(result.input.mesh.frame));
    if (options.field == field::FieldKind::shape_index) {
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
    if (options.field == field::FieldKind::sdf)
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
