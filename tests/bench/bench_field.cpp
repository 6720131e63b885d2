// Benchmark: shape index (--rings 2 and 3, --radius) on the mesh of a 1000x1000 DEM.
//   build/tests/bench/bench_field [size]
#include <tbb/info.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "bench_dem.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;

int main(int argc, char** argv) {
    const int n = argc > 1 ? std::atoi(argv[1]) : 1000;
    const Dem dem = bench::utm_hills(n);
    const auto mesh = mesh::dem_to_mesh(dem);
    std::printf("bench_field: %zu vertices, %d threads\n", mesh.vertex_count(),
                tbb::info::default_concurrency());
    auto run = [&](const char* name, const field::ShapeIndexOptions& options) {
        double best = 1e300;
        for (int i = 0; i < 3; ++i) {
            const auto t0 = std::chrono::steady_clock::now();
            const auto field = field::shape_index_field(mesh, options);
            best = std::min(
                best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        }
        std::printf("shape index %-12s %.3f s  %.2f M vertices/s\n", name, best,
                    mesh.vertex_count() / best / 1e6);
    };
    field::ShapeIndexOptions rings2, rings3, radius;
    rings3.rings = 3;
    radius.radius = 75;
    run("--rings 2", rings2);
    run("--rings 3", rings3);
    run("--radius 75", radius);
    return 0;
}
