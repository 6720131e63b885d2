// Benchmark: the region graph and every segment output of a 1000x1000 DEM cut into about
// 2000 jagged regions (jittered-grid Voronoi cells).
//   build/tests/bench/bench_outputs [size] [regions]
#include <malloc.h>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "bench_dem.hpp"
#include "bench_main.hpp"
#include "bench_measure.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/io/write_adjacency.hpp"
#include "terrain/io/write_label_raster.hpp"
#include "terrain/io/write_preview.hpp"
#include "terrain/io/write_region_polygons.hpp"
#include "terrain/io/write_segment_outputs.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/segment/regions.hpp"

using namespace terrain;

namespace {

double seconds(const std::function<void()>& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Seconds of f, and the bytes its peak resident set rose above the set before it (the peak
// is reset first, through /proc/self/clear_refs, and the heap's free pages given back, so
// that what f allocates shows).
std::array<double, 2> seconds_and_peak(const std::function<void()>& f) {
    malloc_trim(0);
    std::ofstream("/proc/self/clear_refs") << "5";
    const double before = bench::status_kb("VmRSS");
    const double s = seconds(f);
    return {s, (bench::status_kb("VmHWM") - before) * 1024.0};
}

// A small deterministic hash in [0,1).
double hash(std::uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x / 4294967296.0;
}

}  // namespace

static int run_bench(int argc, char** argv) {
    const int n = argc > 1 ? std::atoi(argv[1]) : 1000;
    const int wanted = argc > 2 ? std::atoi(argv[2]) : 2000;
    const Dem dem = bench::utm_hills(n);
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto field = field::vertex_field(mesh, &dem, {});

    // Seeds on a jittered grid; each vertex to the nearest seed of the 3x3 cells around it,
    // the distance jagged by a per-pixel hash so the boundaries are rough.
    const int cells = std::max(1, static_cast<int>(std::lround(std::sqrt(double(wanted)))));
    const double size = double(n) / cells;
    auto seed = [&](int i, int j) {
        const auto k = static_cast<std::uint32_t>(j * cells + i);
        return std::array<double, 2>{(i + 0.2 + 0.6 * hash(2 * k)) * size,
                                     (j + 0.2 + 0.6 * hash(2 * k + 1)) * size};
    };
    std::vector<std::uint32_t> labels(mesh.vertex_count());
    for (std::size_t v = 0; v < labels.size(); ++v) {
        const int c = mesh.vertex_pixel[v] % n, r = mesh.vertex_pixel[v] / n;
        const int ci = std::min(cells - 1, static_cast<int>(c / size));
        const int cj = std::min(cells - 1, static_cast<int>(r / size));
        double best = 1e300;
        for (int j = std::max(0, cj - 1); j <= std::min(cells - 1, cj + 1); ++j)
            for (int i = std::max(0, ci - 1); i <= std::min(cells - 1, ci + 1); ++i) {
                const auto s = seed(i, j);
                const double d = std::hypot(c - s[0], r - s[1]) +
                                 2.0 * hash(static_cast<std::uint32_t>(v * 31 + j * cells + i));
                if (d < best) {
                    best = d;
                    labels[v] = static_cast<std::uint32_t>(j * cells + i + 1);
                }
            }
    }
    const auto count = static_cast<std::uint32_t>(cells * cells);

    const auto dir = std::filesystem::temp_directory_path() / "terrain_bench_outputs";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    auto path = [&](const char* name) { return (dir / name).string(); };

    segment::RegionGraph graph;
    std::vector<std::uint32_t> pixels;
    std::vector<float> field_pixels;
    std::printf("bench_outputs: %dx%d DEM, %zu vertices, %u regions\n", n, n, mesh.vertex_count(),
                count);
    std::printf("region_graph         %.3f s\n",
                seconds([&] { graph = segment::region_graph(mesh, field, labels, count, &dem); }));
    std::printf("  %zu edges\n", graph.edges.size());
    std::printf("label_pixels         %.3f s\n",
                seconds([&] { pixels = segment::label_pixels(mesh, dem, labels); }));
    field_pixels = field::field_to_pixels(mesh, dem, field);
    std::printf("labels.tif           %.3f s\n", seconds([&] {
                    io::write_label_raster(dem, pixels, graph, path("labels.tif"), true);
                }));
    // The polygons' memory: their peak above what was held before, per pixel.
    const double px = double(dem.width) * double(dem.height);
    const auto geojson = seconds_and_peak(
        [&] { io::write_region_polygons(dem, pixels, graph, path("regions.geojson"), true); });
    std::printf("regions.geojson      %.3f s  %.2f M pixels/s  peak +%.1f MB  %.2f bytes/pixel\n",
                geojson[0], px / geojson[0] / 1e6, geojson[1] / 1e6, geojson[1] / px);
    io::RegionPolygonOptions gpkg;
    gpkg.driver = "GPKG";
    const auto geopackage = seconds_and_peak(
        [&] { io::write_region_polygons(dem, pixels, graph, path("regions.gpkg"), true, gpkg); });
    std::printf("regions.gpkg         %.3f s  %.2f M pixels/s  peak +%.1f MB  %.2f bytes/pixel\n",
                geopackage[0], px / geopackage[0] / 1e6, geopackage[1] / 1e6, geopackage[1] / px);
    std::printf("adjacency.json       %.3f s\n",
                seconds([&] { io::write_adjacency_json(graph, path("adjacency.json"), true); }));
    std::printf("adjacency.graphml    %.3f s\n", seconds([&] {
                    io::write_adjacency_graphml(graph, path("adjacency.graphml"), true);
                }));
    std::printf("adjacency.geojson    %.3f s\n", seconds([&] {
                    io::write_adjacency_geojson(graph, path("adjacency.geojson"), true);
                }));
    std::printf("preview.png          %.3f s\n", seconds([&] {
                    io::write_preview_png(dem, field_pixels, pixels, path("preview.png"), true);
                }));
    io::SegmentOutputOptions all;
    all.overwrite = true;
    std::printf("write_segment_outputs %.3f s (all of the DEM's files)\n", seconds([&] {
                    io::write_segment_outputs(dir.string(), mesh, field, labels, graph, &dem, all);
                }));
    for (const auto& e : std::filesystem::directory_iterator(dir))
        std::printf("  %-22s %8.1f kB\n", e.path().filename().c_str(), e.file_size() / 1e3);
    return 0;
}

int main(int argc, char** argv) {
    return terrain::bench::bench_main(
        argc, argv,
        "bench_outputs [size] [regions]: the region graph and every segment output of a size x "
        "size DEM cut into about `regions` regions.",
        run_bench);
}
