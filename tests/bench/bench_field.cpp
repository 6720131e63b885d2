// Benchmark: shape index on the mesh of a 1000x1000 DEM of 30 m pixels: --rings 2 and 3, and
// --radius of 2, 5, 10 and 20 pixels by the grid method (and by the mesh method up to 10
// pixels, whose cost grows with the number of pixels in the disk).
//   build/tests/bench/bench_field [size] [runs] [only: run the cases whose name has this]
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "bench_dem.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;

int main(int argc, char** argv) {
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
        if (name.find(only) == std::string::npos) return;
        double best = 1e300;
        for (int i = 0; i < runs; ++i) {
            const auto t0 = std::chrono::steady_clock::now();
            const auto field = field::shape_index_field(mesh, options);
            best = std::min(
                best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        }
        if (rings2 == 0) rings2 = best;
        std::printf("shape index %-28s %.3f s  %5.2f M vertices/s  %5.2fx --rings 2\n",
                    name.c_str(), best, mesh.vertex_count() / best / 1e6, best / rings2);
    };
    field::ShapeIndexOptions rings2_options, rings3;
    rings3.rings = 3;
    run("--rings 2", rings2_options);
    run("--rings 3", rings3);
    for (const auto method : {field::ShapeIndexMethod::grid, field::ShapeIndexMethod::mesh})
        for (int r : {2, 5, 10, 20}) {
            if (method == field::ShapeIndexMethod::mesh && r > 10) continue;
            field::ShapeIndexOptions options;
            options.radius = r * pixel;
            options.method = method;
            char name[64];
            std::snprintf(name, sizeof name, "--radius %g (%d px), %s", options.radius, r,
                          method == field::ShapeIndexMethod::grid ? "grid" : "mesh");
            run(name, options);
        }
    return 0;
}
