// Benchmark: shape index on the mesh of a 1000x1000 DEM of 30 m pixels: --rings 2 and 3, and
// --radius of 2, 5, 10, 20 and 40 pixels with the disk window (grid method: summed-area
// tables, a cost independent of the radius) and the ball window (grid method, and the mesh
// method up to 10 pixels, whose cost grows with the number of pixels in the ball). Prints
// seconds, vertices per second, the ratio to --rings 2 and the peak resident bytes per pixel.
//   build/tests/bench/bench_field [size] [runs] [only: run the cases whose name has one of
//   these '|'-separated strings; --rings 2 always runs, as the reference]
#include <sys/resource.h>
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "bench_dem.hpp"
#include "bench_main.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;

static int run_bench(int argc, char** argv) {
    const int n = argc > 1 ? std::atoi(argv[1]) : 1000;
    const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
    const std::string only = argc > 3 ? argv[3] : "";
    const Dem dem = bench::utm_hills(n);
    const double pixel = dem.transform[1];
    const auto mesh = mesh::dem_to_mesh(dem);
    std::printf("bench_field: %zu vertices, %d threads, best of %d\n", mesh.vertex_count(),
                tbb::info::default_concurrency(), runs);
    double rings2 = 0;
    auto run = [&](const std::string& name, const field::ShapeIndexOptions& options) {
        bool wanted = only.empty() || name == "--rings 2";
        for (std::size_t at = 0; !wanted && at <= only.size();) {
            const auto end = std::min(only.find('|', at), only.size());
            wanted = name.find(only.substr(at, end - at)) != std::string::npos;
            at = end + 1;
        }
        if (!wanted) return;
        double best = 1e300;
        for (int i = 0; i < runs; ++i) {
            const auto t0 = std::chrono::steady_clock::now();
            const auto field = field::shape_index_field(mesh, options);
            best = std::min(
                best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        }
        if (rings2 == 0) rings2 = best;
        std::printf("shape index %-36s %.3f s  %5.2f M vertices/s  %5.2fx --rings 2\n",
                    name.c_str(), best, mesh.vertex_count() / best / 1e6, best / rings2);
    };
    field::ShapeIndexOptions rings2_options, rings3;
    rings3.rings = 3;
    run("--rings 2", rings2_options);
    run("--rings 3", rings3);
    struct Case {
        field::ShapeIndexWindow window;
        field::ShapeIndexMethod method;
        int max_pixels;
    };
    for (const auto& c : {Case{field::ShapeIndexWindow::disk, field::ShapeIndexMethod::grid, 40},
                          Case{field::ShapeIndexWindow::ball, field::ShapeIndexMethod::grid, 20},
                          Case{field::ShapeIndexWindow::ball, field::ShapeIndexMethod::mesh, 10}})
        for (int r : {2, 5, 10, 20, 40}) {
            if (r > c.max_pixels) continue;
            field::ShapeIndexOptions options;
            options.radius = r * pixel;
            options.method = c.method;
            options.window = c.window;
            char name[64];
            std::snprintf(name, sizeof name, "--radius %g (%d px), %s, %s", options.radius, r,
                          c.window == field::ShapeIndexWindow::disk ? "disk" : "ball",
                          c.method == field::ShapeIndexMethod::grid ? "grid" : "mesh");
            run(name, options);
        }
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    std::printf("peak resident %.0f MB, %.0f bytes per pixel (DEM, mesh and one field)\n",
                usage.ru_maxrss / 1024.0, usage.ru_maxrss * 1024.0 / mesh.vertex_count());
    return 0;
}

int main(int argc, char** argv) {
    return terrain::bench::bench_main(
        argc, argv,
        "bench_field [size] [runs] [only]: the shape index's fits on a size x size DEM of 30 m "
        "pixels (default 1000), each case `runs` times; `only`: the cases whose name holds one of "
        "these '|'-separated strings (--rings 2 always runs).",
        run_bench);
}
