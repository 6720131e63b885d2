// Benchmark: the growing stage of `terrain segment`: the regions grown on the simplified Reeb
// graph, the absorbed vertices divided among them by the flooding (in parts of the vertices
// on every thread; then again in order, one offer at a time, for comparison), and the region
// graph. On a DEM given (a global grid of tests/bench/
// make_global_dem.py) or a synthetic Vesta tile of the size given; the stages before it run
// once, each step of the growing three times (best wall time, and the calling thread's CPU
// time). It holds every stage's arrays, unlike `terrain segment`, which frees and parks them:
// about 140 bytes a vertex, so not the 265 M pixel grid on a 24 GiB machine (killed there).
//   build/tests/bench/bench_grow [DEM | size]

#include <cstdio>
#include <cstdlib>
#include <string>

#include "../../libterrain/src/segment/divide_absorbed_internal.hpp"
#include "bench_main.hpp"
#include "bench_measure.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/geo/georeference.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"
#include "terrain/reeb/simplify.hpp"
#include "terrain/segment/divide_absorbed.hpp"
#include "terrain/segment/grow_regions.hpp"
#include "terrain/segment/regions.hpp"
#include "terrain/synth/crater_field.hpp"

using namespace terrain;

using bench::best_of;

static int run_bench(int argc, char** argv) {
    const std::string arg = argc > 1 ? argv[1] : "1000";
    Dem dem;
    if (arg.find_first_not_of("0123456789") == std::string::npos) {
        synth::VestaTileOptions options;
        options.width = options.height = std::atoi(arg.c_str());
        dem = synth::generate_vesta_tile(options);
        geo::georeference(dem);
    } else {
        dem = io::read_dem(arg);
    }
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto field = field::shape_index_field(mesh);
    reeb::SimplifyOptions thresholds;  // the defaults of `terrain segment`
    thresholds.persistence = 10;
    thresholds.area_ratio = 0.5;
    const auto simplified = reeb::simplify(mesh, reeb::build_reeb_graph(mesh, field), thresholds);
    const double nv = static_cast<double>(mesh.vertex_count());
    std::printf("bench_grow: %s, %zu vertices, %zu nodes after the simplification\n", arg.c_str(),
                mesh.vertex_count(), simplified.graph.node_count());

    segment::Segmentation grown;
    double cpu = 0;
    double t = best_of(
        3, [&] { grown = segment::grow_regions(mesh, simplified.graph, {}); }, &cpu);
    std::printf("grow regions     %7.3f s (CPU %7.3f)  %6.2f M vertices/s  %zu regions\n", t, cpu,
                nv / t / 1e6, std::size_t{grown.region_count});
    segment::Segmentation divided;
    segment::DivideCounts counts;
    t = best_of(
        3,
        [&] {
            divided = grown;
            counts = segment::divide_absorbed(mesh, simplified.graph, field, simplified.absorbed,
                                              divided, nullptr, {});
        },
        &cpu);
    std::printf("divide absorbed  %7.3f s (CPU %7.3f)  %6.2f M vertices/s  %zu absorbed\n", t, cpu,
                nv / t / 1e6, counts.absorbed);
    // The same division with its flooding in order, one offer at a time (the parts' reference:
    // the same labels, checked).
    segment::Segmentation in_order;
    t = best_of(
        3,
        [&] {
            in_order = grown;
            segment::internal::divide_absorbed(mesh, simplified.graph, field, simplified.absorbed,
                                               in_order, nullptr, {}, 1);
        },
        &cpu);
    std::printf("  in order       %7.3f s (CPU %7.3f)  %6.2f M vertices/s  %s labels\n", t, cpu,
                nv / t / 1e6, in_order.labels == divided.labels ? "the same" : "OTHER");
    if (in_order.labels != divided.labels) return 1;
    segment::RegionGraph regions;
    t = best_of(
        3,
        [&] {
            regions =
                segment::region_graph(mesh, field, divided.labels, divided.region_count, &dem, {});
        },
        &cpu);
    std::printf(
        "region graph     %7.3f s (CPU %7.3f)  %6.2f M vertices/s  %zu regions, %zu edges\n", t,
        cpu, nv / t / 1e6, regions.regions.size(), regions.edges.size());
    // The whole benchmark's peak: the mesh, the field, the graphs and the growing's arrays.
    std::printf("peak resident set %.0f bytes/vertex\n", bench::status_kb("VmHWM") * 1024.0 / nv);
    return 0;
}

int main(int argc, char** argv) {
    return terrain::bench::bench_main(
        argc, argv,
        "bench_grow [DEM | size]: the growing stage (regions, division of the absorbed vertices, "
        "region graph) on a DEM or a size x size synthetic Vesta tile.",
        run_bench);
}
