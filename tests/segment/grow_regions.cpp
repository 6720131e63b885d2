#include <tbb/global_control.h>
#include <tbb/task_scheduler_observer.h>
#include <catch2/catch.hpp>

#include <atomic>

#include "support/test_meshes.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/reeb/simplify.hpp"
#include "terrain/segment/grow_regions.hpp"

using namespace terrain;

namespace {

// Number of mesh-connected pieces of each region (index label-1).
std::vector<int> pieces(const TriangleMesh& mesh, const segment::Segmentation& s) {
    return test::region_pieces(mesh, s.labels, s.region_count);
}

struct Case {
    TriangleMesh mesh;
    reeb::ReebGraph graph;
};

Case vesta_case(double area_ratio) {
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    Case c;
    c.mesh = mesh::dem_to_mesh(dem);
    const auto f = field::shape_index_field(c.mesh);
    reeb::SimplifyOptions o;
    o.persistence = 10;
    o.area_ratio = area_ratio;
    c.graph = reeb::simplify(c.mesh, reeb::build_reeb_graph(c.mesh, f), o).graph;
    return c;
}

}  // namespace

TEST_CASE("Regions: one per extremum, every vertex labelled, every region connected", "[segment]") {
    const auto c = vesta_case(0.5);
    const auto summary = reeb::summarize(c.graph);
    for (auto cost : {segment::GrowCost::graph, segment::GrowCost::standard}) {
        segment::GrowOptions o;
        o.cost = cost;
        const auto s = segment::grow_regions(c.mesh, c.graph, o);
        INFO(segment::to_string(cost));
        CHECK(s.region_count == summary.minima + summary.maxima);
        REQUIRE(s.labels.size() == c.mesh.vertex_count());
        CHECK(std::all_of(s.labels.begin(), s.labels.end(),
                          [&](std::uint32_t l) { return l >= 1 && l <= s.region_count; }));
        const auto p = pieces(c.mesh, s);
        CHECK(std::count(p.begin(), p.end(), 1) == static_cast<long>(s.region_count));
        CHECK(s.relaxed_nodes == 0);
        // Seeds are in their own regions, numbered by their lowest vertex.
        for (std::uint32_t r = 0; r < s.region_count; ++r) {
            const auto seed = s.seeds[r];
            const auto v =
                c.graph.node_vertices[static_cast<std::size_t>(c.graph.node_vertex_offsets[seed])];
            CHECK(s.labels[static_cast<std::size_t>(v)] == r + 1);
        }
    }
}

TEST_CASE("The order a node's vertices are visited in does not change the regions", "[segment]") {
    // Nodes walked by their lists (never in vertex order), from 1/64 of the vertices (the
    // default), and every node walked in vertex order: the candidates are sets either way.
    const auto c = vesta_case(0.5);
    std::size_t biggest = 0;
    for (std::size_t n = 0; n < c.graph.node_count(); ++n)
        biggest = std::max<std::size_t>(biggest, std::size_t(c.graph.node_vertex_offsets[n + 1] -
                                                             c.graph.node_vertex_offsets[n]));
    REQUIRE(biggest * 64 >= c.mesh.vertex_count());  // the default walks one node at least
    for (auto cost : {segment::GrowCost::graph, segment::GrowCost::standard}) {
        INFO(segment::to_string(cost));
        segment::GrowOptions o;
        o.cost = cost;
        const auto by_default = segment::grow_regions(c.mesh, c.graph, o);
        o.walk_share = 0;
        const auto by_lists = segment::grow_regions(c.mesh, c.graph, o);
        o.walk_share = c.mesh.vertex_count();
        const auto all_walked = segment::grow_regions(c.mesh, c.graph, o);
        CHECK(by_default.labels == by_lists.labels);
        CHECK(all_walked.labels == by_lists.labels);
        CHECK(by_default.seeds == by_lists.seeds);
        CHECK(by_default.relaxed_nodes == by_lists.relaxed_nodes);
    }
}

TEST_CASE("Region growing is deterministic across runs and thread counts", "[segment]") {
    // The pipeline before it runs in parallel (the mesh, the shape index over blocks of 512
    // vertices, the join and split trees side by side): on the 512 x 512 Vesta tile two
    // threads split the work, and the labels must be those of one thread.
    struct WorkerCount : tbb::task_scheduler_observer {
        std::atomic<int> joined{0};
        WorkerCount() { observe(true); }
        ~WorkerCount() override { observe(false); }
        void on_scheduler_entry(bool is_worker) override { joined += is_worker ? 1 : 0; }
    };
    const auto labels_with = [](int threads, int& workers) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                  static_cast<std::size_t>(threads));
        WorkerCount count;
        const auto c = vesta_case(0.1);
        REQUIRE(c.mesh.vertex_count() > 100 * 512);
        auto labels = segment::grow_regions(c.mesh, c.graph).labels;
        workers = count.joined;
        return labels;
    };
    int workers = 0;
    const auto one = labels_with(1, workers);
    const auto two = labels_with(2, workers);
    CHECK(workers > 0);  // a second thread took part
    CHECK(two == one);
    CHECK(labels_with(2, workers) == one);  // and again
}

TEST_CASE("A constant field is one region, a genus-2 plate keeps regions connected", "[segment]") {
    const auto plate = test::plate_mesh(20, 8, 2);
    const std::vector<float> flat(plate.vertex_count(), 50.f);
    const auto g = reeb::build_reeb_graph(plate, flat);
    const auto s = segment::grow_regions(plate, g);
    CHECK(s.region_count == 1);
    const auto noise = test::noise_field(plate.vertex_count(), 4);
    reeb::SimplifyOptions o;
    o.persistence = 20;
    const auto simple = reeb::simplify(plate, reeb::build_reeb_graph(plate, noise), o);
    for (auto cost : {segment::GrowCost::graph, segment::GrowCost::standard}) {
        segment::GrowOptions go;
        go.cost = cost;
        const auto r = segment::grow_regions(plate, simple.graph, go);
        const auto p = pieces(plate, r);
        CHECK(std::count(p.begin(), p.end(), 1) == static_cast<long>(r.region_count));
    }
    segment::GrowOptions bad;
    bad.saddle_penalty = -1;
    CHECK_THROWS_AS(segment::grow_regions(plate, g, bad), Error);
    CHECK_THROWS_AS(segment::parse_grow_cost("cheap"), Error);
}
