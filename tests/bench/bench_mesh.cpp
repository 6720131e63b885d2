// Benchmark: DEM -> mesh on a 1000x1000 grid, in the map frame (projected Earth CRS) and the
// body frame (a lon/lat grid on Vesta). Prints throughput and bytes per vertex.
//   build/tests/bench/bench_mesh [size]
#include <tbb/info.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "bench_main.hpp"
#include "terrain/geo/georeference.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;

namespace {

Dem synthetic(int n, const std::string& crs, const GeoTransform& transform, double base) {
    Dem dem;
    dem.width = dem.height = n;
    dem.crs_wkt = crs;
    dem.transform = transform;
    dem.has_transform = true;
    geo::georeference(dem);
    dem.elevation = base > 0 ? ElevationKind::radius : ElevationKind::height;
    dem.values.resize(std::size_t(n) * n);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            dem.values[std::size_t(r) * n + c] = base +
                                                 200 * std::sin(c * 0.05) * std::cos(r * 0.037) +
                                                 30 * std::sin(c * 0.9 + r * 1.3);
    return dem;
}

void run(const char* name, const Dem& dem) {
    double best = 1e300;
    TriangleMesh mesh;
    for (int i = 0; i < 3; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        mesh = mesh::dem_to_mesh(dem);
        best = std::min(
            best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf(
        "%-28s %9zu vertices %9zu triangles  %.3f s  %.2f M vertices/s  %.1f bytes/vertex\n", name,
        mesh.vertex_count(), mesh.triangle_count(), best, mesh.vertex_count() / best / 1e6,
        double(mesh.memory_bytes()) / double(mesh.vertex_count()));
}

}  // namespace

static int run_bench(int argc, char** argv) {
    const int n = argc > 1 ? std::atoi(argv[1]) : 1000;
    std::printf("bench_mesh: %dx%d DEM, %d threads\n", n, n, tbb::info::default_concurrency());
    run("map frame (UTM 11N, 30 m)",
        synthetic(n, "EPSG:32611", {400000, 30, 0, 3800000, 0, -30}, 0));
    run("body frame (Vesta lon/lat)", synthetic(n, "+proj=longlat +R=255000 +no_defs",
                                                {10, 1.0 / 64, 0, -20, 0, -1.0 / 64}, 255000));
    return 0;
}

int main(int argc, char** argv) {
    return terrain::bench::bench_main(
        argc, argv,
        "bench_mesh [size]: DEM to mesh on a size x size grid (default 1000), map and body frames.",
        run_bench);
}
