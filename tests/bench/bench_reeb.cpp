// Benchmark: Reeb graph construction and simplification (single thread, as both are) on the
// shape index field of a synthetic 1000x1000 Vesta tile (craters plus roughness: a noisy
// field where a large share of vertices are critical).
//   build/tests/bench/bench_reeb [size]
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "bench_main.hpp"
#include "bench_measure.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/geo/georeference.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"
#include "terrain/reeb/simplify.hpp"
#include "terrain/synth/crater_field.hpp"

using namespace terrain;

using bench::best_of;

static int run_bench(int argc, char** argv) {
    synth::VestaTileOptions options;
    options.width = options.height = argc > 1 ? std::atoi(argv[1]) : 1000;
    Dem dem = synth::generate_vesta_tile(options);
    geo::georeference(dem);
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto field = field::shape_index_field(mesh);
    const double nv = static_cast<double>(mesh.vertex_count());

    reeb::ReebGraph graph;
    double c_build = 0;
    const double t_build = best_of(
        3, [&] { graph = reeb::build_reeb_graph(mesh, field); }, &c_build);
    double t_single = 0, c_single = 0;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        t_single = best_of(
            3, [&] { graph = reeb::build_reeb_graph(mesh, field); }, &c_single);
    }
    const auto s = reeb::summarize(graph);
    std::printf(
        "bench_reeb: %zu vertices, shape index field, %zu critical nodes (%.1f%%), %zu arcs, "
        "%d cores\n",
        mesh.vertex_count(), s.critical, 100.0 * s.critical / nv, s.arcs,
        tbb::info::default_concurrency());
    std::printf("construction, 1 thread   %.3f s  %.2f M vertices/s  %.1f bytes/vertex\n", t_single,
                nv / t_single / 1e6, graph.memory_bytes() / nv);
    std::printf(
        "construction, all cores  %.3f s  %.2f M vertices/s (join and split trees side "
        "by side)\n",
        t_build, nv / t_build / 1e6);
    for (const double ratio : {0.1, 0.5}) {
        reeb::SimplifyOptions so;
        so.persistence = 10;
        so.area_ratio = ratio;
        reeb::SimplifyResult result;
        double c = 0;
        const double t = best_of(
            3, [&] { result = reeb::simplify(mesh, graph, so); }, &c);
        const auto r = reeb::summarize(result.graph);
        std::printf(
            "simplify P=10 A=%.1f%%  %.3f s  %.2f M vertices/s  %zu -> %zu critical nodes, "
            "%.1f bytes/vertex\n",
            ratio, t, nv / t / 1e6, s.critical, r.critical, result.graph.memory_bytes() / nv);
    }
    return 0;
}

int main(int argc, char** argv) {
    return terrain::bench::bench_main(
        argc, argv,
        "bench_reeb [size]: Reeb graph construction and simplification on a size x size synthetic "
        "Vesta tile (default 1000).",
        run_bench);
}
