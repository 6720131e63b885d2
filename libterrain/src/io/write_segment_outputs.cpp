#include <gdal_priv.h>

#include <tbb/parallel_invoke.h>

#include <filesystem>
#include <mutex>

#include "gdal_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/write_adjacency.hpp"
#include "terrain/io/write_label_raster.hpp"
#include "terrain/io/write_mesh_labels.hpp"
#include "terrain/io/write_preview.hpp"
#include "terrain/io/write_region_polygons.hpp"
#include "terrain/io/write_segment_outputs.hpp"

namespace terrain::io {
namespace {

// "regions.geojson", or regions.<the driver's extension> ("regions.gpkg").
std::string polygon_file(const std::string& driver_name) {
    if (driver_name == "GeoJSON") return "regions.geojson";
    ensure_gdal_registered();
    GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(driver_name.c_str());
    const char* ext = driver ? driver->GetMetadataItem(GDAL_DMD_EXTENSION) : nullptr;
    if (!ext || !*ext)
        throw Error("write", "'" + driver_name +
                                 "' is not an OGR vector driver that creates "
                                 "files; try GeoJSON or GPKG");
    return std::string("regions.") + ext;
}

}  // namespace

std::vector<std::string> write_segment_outputs(const std::string& dir, const TriangleMesh& mesh,
                                               const std::vector<float>& field,
                                               const std::vector<std::uint32_t>& labels,
                                               const segment::RegionGraph& graph, const Dem* dem,
                                               const SegmentOutputOptions& options,
                                               const ProgressFn& progress) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw Error("write", "'" + dir + "' is not a directory; create it first");
    auto in_dir = [&](const std::string& name) { return (fs::path(dir) / name).string(); };
    std::vector<std::string> names;
    if (dem)
        names = {"labels.tif",        polygon_file(options.polygons.driver),
                 "adjacency.json",    "adjacency.graphml",
                 "adjacency.geojson", "preview.png"};
    else
        names = {"labels.ply", "faces.seg", "adjacency.json", "adjacency.graphml",
                 "adjacency.geojson"};
    std::vector<std::string> paths;
    for (const auto& name : names) paths.push_back(in_dir(name));
    for (const auto& p : paths) check_output_path(p, options.overwrite);
    if (dem) check_output_path(paths[0] + ".aux.xml", options.overwrite);
    if (dem) check_output_path(label_style_path(paths[0]), options.overwrite);

    const bool overwrite = options.overwrite;
    const double steps = static_cast<double>(paths.size());
    std::size_t done = 0;
    double reported = 0;
    std::mutex progress_mutex;  // the raster writers report from their own threads
    // (Each file a step; the label raster and the polygons also within theirs. They run side
    // by side, so the fraction reported is the highest yet: it never goes back.)
    auto report = [&](double fraction) {
        const std::lock_guard<std::mutex> lock(progress_mutex);
        reported = std::max(reported, fraction);
        report_progress(progress, reported, "write");
    };
    // `fraction` of the way through the next file (after `files` more are done).
    auto within = [&](double fraction, std::size_t files = 0) {
        std::size_t now;
        {
            const std::lock_guard<std::mutex> lock(progress_mutex);
            now = done += files;
        }
        report((double(now) + fraction) / steps);
    };
    auto step = [&] { within(0, 1); };
    const ProgressFn partly = [&](double fraction, std::string_view) {
        within(fraction);
        return true;
    };
    // The adjacency graph's three files (they read the region graph only).
    const auto adjacency = [&] {
        write_adjacency_json(graph, paths[2], overwrite);
        step();
        write_adjacency_graphml(graph, paths[3], overwrite);
        step();
        write_adjacency_geojson(graph, paths[4], overwrite);
        step();
    };
    if (dem) {
        // The raster-based files and the adjacency files are independent: written side by
        // side.
        const auto pixels = segment::label_pixels(mesh, *dem, labels);
        tbb::parallel_invoke(
            [&] {
                write_label_raster(*dem, pixels, graph, paths[0], overwrite,
                                   progress ? partly : ProgressFn{});
                step();
            },
            [&] {
                write_region_polygons(*dem, pixels, graph, paths[1], overwrite, options.polygons,
                                      progress ? partly : ProgressFn{});
                step();
            },
            [&] {
                auto caption = options.preview_caption;
                if (caption.regions == 0) caption.regions = graph.regions.size();
                auto image = render_preview(*dem, field::field_to_pixels(mesh, *dem, field), pixels,
                                            caption);
                if (options.deferred_preview)
                    *options.deferred_preview = std::move(image);
                else
                    write_preview_image(image, paths[5], overwrite);
                step();
            },
            adjacency);
    } else {
        write_labels_ply(mesh, field, labels, paths[0], overwrite, options.field_name);
        step();
        write_faces_seg(mesh, labels, paths[1], overwrite);
        step();
        adjacency();
    }
    return paths;
}

}  // namespace terrain::io
