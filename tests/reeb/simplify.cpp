#include <catch2/catch.hpp>

#include <algorithm>
#include <climits>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string_view>
#include <utility>

#include <tbb/task_arena.h>

#include "../../libterrain/src/reeb/simplifier.hpp"
#include "terrain/internal/core/release.hpp"

#include "support/recording_residency.hpp"
#include "support/test_meshes.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/geo/georeference.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/reeb/simplify.hpp"
#include "terrain/synth/crater_field.hpp"

using namespace terrain;

namespace {

// Critical nodes as (kind, sorted vertex set): comparable between graphs of one mesh.
std::set<std::pair<int, std::vector<std::int32_t>>> critical_nodes(const reeb::ReebGraph& g) {
    std::set<std::pair<int, std::vector<std::int32_t>>> out;
    for (std::size_t n = 0; n < g.node_count(); ++n) {
        if (!g.is_critical(static_cast<std::int32_t>(n))) continue;
        std::vector<std::int32_t> vs(g.node_vertices.begin() + g.node_vertex_offsets[n],
                                     g.node_vertices.begin() + g.node_vertex_offsets[n + 1]);
        std::sort(vs.begin(), vs.end());
        out.insert({static_cast<int>(g.node_kinds[n]), vs});
    }
    return out;
}

reeb::SimplifyResult simplified(const TriangleMesh& mesh, const std::vector<float>& f, double p,
                                double a) {
    const auto g = reeb::build_reeb_graph(mesh, f);
    reeb::SimplifyOptions o;
    o.persistence = p;
    o.area_ratio = a;
    auto r = reeb::simplify(mesh, g, o);
    INFO(reeb::check_reeb_graph(r.graph, r.field));
    REQUIRE(reeb::check_reeb_graph(r.graph, r.field).empty());
    return r;
}

struct Sample {
    Dem dem;
    TriangleMesh mesh;
    std::vector<float> si;
};
const Sample& vesta() {
    static const Sample s = [] {
        Sample x;
        x.dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
        x.mesh = mesh::dem_to_mesh(x.dem);
        x.si = field::shape_index_field(x.mesh);
        return x;
    }();
    return s;
}

// Checks a simplification against the counts it reports: every cancellation removes one
// critical node and one arc, and so does every node made regular (its two arcs merge).
void check_path(const reeb::ReebGraph& before, const reeb::SimplifyResult& r) {
    const auto b = reeb::summarize(before), a = reeb::summarize(r.graph);
    const auto cancelled = r.saddle_extremum + r.extremum_extremum;
    CHECK(b.critical - a.critical == cancelled + r.made_regular);
    CHECK(b.arcs - a.arcs == cancelled + r.made_regular);
    CHECK(r.turned_made_regular <= r.made_regular);
    CHECK(r.turned_made_regular + r.turned_made_extremum <= r.arcs_turned);
}

}  // namespace

TEST_CASE("Two hills: persistence above the smaller hill cuts it down, keeps the high one",
          "[simplify]") {
    // Hills 10 and 4 high over a plane tilted by 0.001 per pixel; the saddle between them is
    // near the plane.
    const auto dem = test::grid_dem(40, 20, [](int c, int r) {
        const double a = std::hypot(c - 10, r - 10), b = std::hypot(c - 30, r - 10);
        return 10 * std::exp(-a * a / 20) + 4 * std::exp(-b * b / 20) + 0.001 * (c + 2 * r);
    });
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto f = field::height_field(mesh, &dem);
    const auto before = reeb::summarize(reeb::build_reeb_graph(mesh, f));
    REQUIRE(before.maxima == 2);
    const auto r = simplified(mesh, f, 5, 0);
    const auto after = reeb::summarize(r.graph);
    CHECK(after.maxima == 1);
    CHECK(after.saddles < before.saddles);
    CHECK(r.saddle_extremum >= 1);
    // The kept maximum is the high hill's top, with its value unchanged.
    float top = 0;
    for (std::size_t n = 0; n < r.graph.node_count(); ++n)
        if (r.graph.node_kinds[n] == reeb::NodeKind::maximum) top = r.graph.node_values[n];
    CHECK(top == Approx(10.03).margin(0.05));
    // The small hill is cut down (to its saddle, or to the midpoint with a minimum).
    const auto p2v = mesh::pixel_to_vertex(mesh, dem);
    const auto small_top = static_cast<std::size_t>(p2v[dem.index(30, 10)]);
    CHECK(r.field[small_top] < f[small_top] - 1.5f);
    // With a threshold above both hills, only extremum-extremum pairs can go; a disk keeps
    // at least one node.
    const auto all = simplified(mesh, f, 1000, 0);
    CHECK(reeb::summarize(all.graph).critical >= 1);
}

TEST_CASE("The rewritten field rebuilds into the same critical nodes", "[simplify]") {
    const auto& s = vesta();
    for (const auto& [p, a] :
         std::vector<std::pair<double, double>>{{10, 0.5}, {10, 0.1}, {5, 0}}) {
        const auto r = simplified(s.mesh, s.si, p, a);
        const auto rebuilt = reeb::build_reeb_graph(s.mesh, r.field);
        INFO("persistence " << p << " area ratio " << a);
        CHECK(critical_nodes(rebuilt) == critical_nodes(r.graph));
        CHECK(reeb::summarize(rebuilt).arcs == reeb::summarize(r.graph).arcs);
    }
    const auto torus = test::plate_mesh(20, 8, 2);
    const auto noise = test::noise_field(torus.vertex_count(), 11);
    const auto r = simplified(torus, noise, 30, 5);
    CHECK(critical_nodes(reeb::build_reeb_graph(torus, r.field)) == critical_nodes(r.graph));
}

TEST_CASE("Arcs turned around elsewhere: their far nodes become regular, loops never turn",
          "[simplify]") {
    // A cancellation moves the kept node's value; an arc of it whose far node is now on the
    // other side turns around, and that far node may be left with one arc below and one
    // above (it must become regular) or become an extremum (its arcs are new candidates).
    // The Vesta sample's shape index meets the first case at area ratio 1 %. On a noisy
    // plate with two holes at 5 % the second case came only from turning both arcs of a
    // loop, which closed the loop in the rewritten field (its graph rebuilt 66 critical
    // nodes against 9): such a cancellation now waits.
    const auto& s = vesta();
    const auto g = reeb::build_reeb_graph(s.mesh, s.si);
    for (const double a : {0.5, 1.0}) {
        INFO("Vesta, area ratio " << a);
        const auto r = simplified(s.mesh, s.si, 0, a);  // checks the graph
        check_path(g, r);
        CHECK(critical_nodes(reeb::build_reeb_graph(s.mesh, r.field)) == critical_nodes(r.graph));
        CHECK(r.arcs_turned >= 1);
        if (a == 1.0) CHECK(r.turned_made_regular >= 1);  // the first case
    }
    const auto plate = test::plate_mesh(80, 40, 2);
    const auto noise = test::noise_field(plate.vertex_count(), 1);
    for (const double a : {3.0, 5.0, 10.0}) {
        INFO("noisy plate with two holes, area ratio " << a);
        const auto r = simplified(plate, noise, 0, a);
        check_path(reeb::build_reeb_graph(plate, noise), r);
        CHECK(r.loop_waits >= 1);
        CHECK(reeb::summarize(r.graph).loops == 2);
        CHECK(critical_nodes(reeb::build_reeb_graph(plate, r.field)) == critical_nodes(r.graph));
    }
}

TEST_CASE("The counts of a simplification tell its path (synthetic tile)", "[simplify]") {
    synth::VestaTileOptions options;
    options.width = options.height = 300;
    Dem dem = synth::generate_vesta_tile(options);
    geo::georeference(dem);
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto si = field::shape_index_field(mesh);
    const auto g = reeb::build_reeb_graph(mesh, si);
    for (const auto& [p, a] :
         std::vector<std::pair<double, double>>{{0, 0.1}, {0, 0.5}, {10, 0.1}, {10, 0.5}, {0, 2}}) {
        INFO("persistence " << p << " area ratio " << a);
        const auto r = simplified(mesh, si, p, a);  // checks the graph
        check_path(g, r);
        CHECK(r.saddle_extremum > 0);
        CHECK(r.made_regular > 0);
        CHECK(critical_nodes(reeb::build_reeb_graph(mesh, r.field)) == critical_nodes(r.graph));
    }
}

TEST_CASE("Loops survive any thresholds", "[simplify]") {
    const auto plate = test::plate_mesh(20, 8, 2);
    const auto noise = test::noise_field(plate.vertex_count(), 3);
    const auto r = simplified(plate, noise, 1e9, 100);
    CHECK(reeb::summarize(r.graph).loops == 2);
    const auto torus = test::torus_mesh(3, 1, 32, 16, true);
    std::vector<float> z(torus.vertex_count());
    for (std::size_t v = 0; v < z.size(); ++v) z[v] = static_cast<float>(torus.position(v)[2]);
    CHECK(reeb::summarize(simplified(torus, z, 1e9, 100).graph).loops == 1);
}

TEST_CASE("Raising a threshold never adds nodes (Vesta sample)", "[simplify]") {
    const auto& s = vesta();
    const auto g = reeb::build_reeb_graph(s.mesh, s.si);
    std::size_t last = reeb::summarize(g).critical;
    for (double a : {0.0, 0.1, 0.25, 0.5, 1.0, 2.0, 6.0}) {
        reeb::SimplifyOptions o;
        o.persistence = 10;
        o.area_ratio = a;
        const auto n = reeb::summarize(reeb::simplify(s.mesh, g, o).graph).critical;
        INFO("area ratio " << a);
        CHECK(n <= last);
        last = n;
    }
    last = reeb::summarize(g).critical;
    for (double p : {0.0, 1.0, 5.0, 10.0, 20.0, 50.0}) {
        reeb::SimplifyOptions o;
        o.persistence = p;
        const auto n = reeb::summarize(reeb::simplify(s.mesh, g, o).graph).critical;
        INFO("persistence " << p);
        CHECK(n <= last);
        last = n;
    }
}

TEST_CASE("Simplification is deterministic and leaves no candidate", "[simplify]") {
    const auto& s = vesta();
    const auto a = simplified(s.mesh, s.si, 10, 0.5);
    const auto b = simplified(s.mesh, s.si, 10, 0.5);
    CHECK(a.field == b.field);
    CHECK(a.graph.arcs == b.graph.arcs);
    // Handing the graph over (it is freed as soon as it is copied) changes nothing.
    reeb::SimplifyOptions o;
    o.persistence = 10;
    o.area_ratio = 0.5;
    auto taken = reeb::build_reeb_graph(s.mesh, s.si);
    const auto c = reeb::simplify(s.mesh, std::move(taken), o);
    CHECK(c.field == a.field);
    CHECK(c.graph.arcs == a.graph.arcs);
    CHECK(c.graph.arc_nodes == a.graph.arc_nodes);
    CHECK(c.graph.node_vertices == a.graph.node_vertices);
    CHECK(c.graph.node_lower_links == a.graph.node_lower_links);
    CHECK(taken.arcs.empty());
    // ... and the rest once the result is written: nothing of it is held while regions grow.
    CHECK(taken.node_vertices.capacity() == 0);
    CHECK(taken.vertex_nodes.capacity() == 0);
    CHECK(taken.node_vertex_offsets.capacity() == 0);
    CHECK(taken.node_values.capacity() == 0);
    CHECK(taken.node_lower_links.capacity() == 0);
    // No arc with an extremum end (and no parallel twin) is left below the thresholds.
    const auto m = reeb::arc_metrics(s.mesh, a.graph);
    const auto inc = reeb::node_arcs(a.graph);
    for (std::size_t k = 0; k < a.graph.arc_count(); ++k) {
        const auto [lo, hi] = a.graph.arcs[k];
        if (!a.graph.is_extremum(lo) && !a.graph.is_extremum(hi)) continue;
        std::size_t twins = 0;
        for (auto i = inc.offsets[lo]; i < inc.offsets[lo + 1]; ++i)
            twins += a.graph.arcs[inc.arcs[i]] == a.graph.arcs[k];
        if (twins > 1) continue;
        CHECK((m.persistence[k] >= 10 && m.area_ratio[k] >= 0.005));
    }
}

TEST_CASE("The working graph stays in proportion to the mesh on a closed noisy surface",
          "[simplify]") {
    // On a global grid the degenerate maximum that absorbs the cancelled nodes moves from
    // node to node, taking all its arcs along at every cancellation. Their old runs used to
    // stay in the arena: 3.9 M entries (245 bytes per vertex) for this 64 k-vertex Moon, and
    // more than 2^31 entries (a memory overrun) on a 66 M pixel global grid.
    auto dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
    const auto mesh = mesh::dem_to_mesh(dem);
    REQUIRE(mesh.seam_closed);
    const auto si = field::shape_index_field(mesh);
    const auto g = reeb::build_reeb_graph(mesh, si);
    reeb::SimplifyOptions o;
    o.persistence = 10;
    o.area_ratio = 0.5;
    const auto r = reeb::simplify(mesh, g, o);
    check_path(g, r);
    const double per_vertex = double(r.working_bytes) / double(mesh.vertex_count());
    INFO("working graph " << per_vertex << " bytes per vertex");
    CHECK(per_vertex < 100);
    CHECK(critical_nodes(reeb::build_reeb_graph(mesh, r.field)) == critical_nodes(r.graph));
}

TEST_CASE("Simplification thresholds are checked", "[simplify]") {
    const auto mesh = test::plate_mesh(6, 4, 0);
    const auto g = reeb::build_reeb_graph(mesh, test::noise_field(mesh.vertex_count(), 1));
    reeb::SimplifyOptions o;
    o.persistence = -1;
    CHECK_THROWS_WITH(reeb::simplify(mesh, g, o), Catch::Contains("persistence"));
    o.persistence = 0;
    o.area_ratio = 150;
    CHECK_THROWS_WITH(reeb::simplify(mesh, g, o), Catch::Contains("percentage"));
    o.area_ratio = std::nan("");
    CHECK_THROWS_AS(reeb::simplify(mesh, g, o), Error);
}

TEST_CASE("Simplification refuses a graph whose lists hold arc ends or shared nodes",
          "[simplify]") {
    const auto mesh = test::plate_mesh(12, 10, 0);
    const auto g = reeb::build_reeb_graph(mesh, test::noise_field(mesh.vertex_count(), 3));
    std::vector<std::size_t> listed;  // arcs with regular nodes
    for (std::size_t a = 0; a < g.arc_count(); ++a)
        if (g.arc_offsets[a] < g.arc_offsets[a + 1]) listed.push_back(a);
    REQUIRE(listed.size() >= 2);
    REQUIRE_NOTHROW(reeb::simplify(mesh, g, {}));
    auto end_in_list = g;
    end_in_list.arc_nodes[end_in_list.arc_offsets[listed[0]]] = g.arcs[listed[0]][0];
    CHECK_THROWS_WITH(reeb::simplify(mesh, end_in_list, {}), Catch::Contains("not valid"));
    auto shared = g;
    shared.arc_nodes[shared.arc_offsets[listed[1]]] = g.arc_nodes[g.arc_offsets[listed[0]]];
    CHECK_THROWS_WITH(reeb::simplify(mesh, shared, {}), Catch::Contains("not valid"));
}

TEST_CASE("The simplification's progress never goes back and ends at 1", "[simplify]") {
    // Reported on a clock (at least every quarter second while it runs): the fraction of the
    // work known, cancellations made over those made plus the candidates queued, which new
    // candidates can lower; it is held where it was instead.
    auto dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto si = field::shape_index_field(mesh);
    const auto g = reeb::build_reeb_graph(mesh, si);
    std::vector<double> seen;
    const auto r = reeb::simplify(mesh, g, {}, [&](double fraction, std::string_view message) {
        CHECK(message == "simplify");
        seen.push_back(fraction);
        return true;
    });
    REQUIRE_FALSE(seen.empty());
    CHECK(std::is_sorted(seen.begin(), seen.end()));
    CHECK(seen.front() >= 0);
    CHECK(seen.back() == 1.0);
    // The copy into the working graph (the first quarter) and the output (the last) report
    // their passes: on a large grid each is a long silence otherwise.
    const auto within = [&](double lo, double hi) {
        return std::count_if(seen.begin(), seen.end(), [&](double f) { return f > lo && f < hi; });
    };
    CHECK(within(0, 0.25) >= 2);
    CHECK(within(0.75, 1) >= 3);
    // A callback that cancels stops it with an error.
    CHECK_THROWS_AS(reeb::simplify(mesh, g, {}, [](double, std::string_view) { return false; }),
                    Error);
    CHECK(r.graph.node_count() > 0);
}

namespace {

struct Run {
    reeb::SimplifyResult result;
    std::size_t moved = 0;
    std::string failure;
};
// The simplification with nodes of big_degree arcs or more made big (INT_MAX: none), the big
// nodes checked after every cancellation.
Run simplify_big(const TriangleMesh& mesh, const reeb::ReebGraph& g, double p, double a,
                 int big_degree) {
    reeb::SimplifyOptions o;
    o.persistence = p;
    o.area_ratio = a;
    reeb::internal::Simplifier s(mesh, g, o, big_degree);
    if (big_degree < 64) s.check_each_step();
    Run run;
    s.run({}, run.result);
    run.moved = s.arcs_moved();
    run.failure = s.check_failure();
    return run;
}

// The global Moon sample with pixel noise: a closed noisy surface, where a degenerate maximum
// takes thousands of cancellations down the graph.
TriangleMesh noisy_global_moon() {
    auto dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> noise(-400.0, 400.0);
    for (double& z : dem.values) z += noise(rng);
    return mesh::dem_to_mesh(dem);
}

}  // namespace

TEST_CASE("Big nodes give the same simplification, at any degree they start from",
          "[simplify][big]") {
    // Nodes with many arcs keep them in ordered sets and queue one candidate (big_nodes.cpp);
    // the rule is the same, so the result must be the same bit for bit as with every node
    // scanning its arcs, down to big nodes of 3 arcs (nearly every node) on a closed noisy
    // surface, a tile, and a global grid with a many-armed pole.
    struct Case {
        const char* name;
        TriangleMesh mesh;
    };
    std::vector<Case> cases;
    cases.push_back({"Vesta tile", vesta().mesh});
    cases.push_back(
        {"global Moon", mesh::dem_to_mesh(io::read_dem(test::sample("moon_ldem1_global.tif")))});
    cases.push_back({"noisy global Moon", noisy_global_moon()});
    for (const auto& c : cases) {
        const auto si = field::shape_index_field(c.mesh);
        const auto g = reeb::build_reeb_graph(c.mesh, si);
        for (const auto& [p, a] : {std::pair{10.0, 0.5}, {10.0, 0.1}, {40.0, 3.0}, {0.0, 2.0}}) {
            const Run off = simplify_big(c.mesh, g, p, a, INT_MAX);
            for (const int degree : {3, 8, 48}) {
                INFO(c.name << ", persistence " << p << ", area ratio " << a << ", big from "
                            << degree << " arcs");
                const Run on = simplify_big(c.mesh, g, p, a, degree);
                INFO(on.failure);
                REQUIRE(on.failure.empty());
                CHECK(on.result.field == off.result.field);
                CHECK(on.result.absorbed == off.result.absorbed);
                CHECK(on.result.graph.arcs == off.result.graph.arcs);
                CHECK(on.result.graph.arc_nodes == off.result.graph.arc_nodes);
                CHECK(on.result.graph.node_vertices == off.result.graph.node_vertices);
                CHECK(on.result.graph.node_kinds == off.result.graph.node_kinds);
                CHECK(on.result.saddle_extremum == off.result.saddle_extremum);
                CHECK(on.result.extremum_extremum == off.result.extremum_extremum);
                CHECK(on.result.made_regular == off.result.made_regular);
                CHECK(on.result.arcs_turned == off.result.arcs_turned);
                CHECK(on.result.loop_waits == off.result.loop_waits);
            }
        }
    }
}

TEST_CASE("A moving degenerate extremum costs what changes, not its degree", "[simplify][big]") {
    // On a closed noisy surface one degenerate maximum takes thousands of arcs down the graph,
    // one saddle at a time. Moving all its arcs at every step made the simplification
    // quadratic (79 s for a 1 M pixel global grid); a big node hands its set over whole.
    const auto mesh = noisy_global_moon();
    const auto si = field::shape_index_field(mesh);
    const auto g = reeb::build_reeb_graph(mesh, si);
    const Run big = simplify_big(mesh, g, 10, 0.5, reeb::internal::kBigDegree);
    const Run scanned = simplify_big(mesh, g, 10, 0.5, INT_MAX);
    const double arcs = static_cast<double>(g.arc_count());
    INFO("arcs " << arcs << ", moved with big nodes " << big.moved << ", without "
                 << scanned.moved);
    CHECK(static_cast<double>(big.moved) < 4 * arcs);
    CHECK(static_cast<double>(scanned.moved) > 20 * arcs);  // the case is the hard one
    CHECK(big.result.field == scanned.result.field);
}

namespace {

// The Vesta tile's graph with the paper's thresholds, and a check that a result given the
// graph handed over is the one it gives lent.
reeb::SimplifyOptions paper_thresholds() {
    reeb::SimplifyOptions o;
    o.persistence = 10;
    o.area_ratio = 0.5;
    return o;
}
void check_same_result(const reeb::SimplifyResult& given, const reeb::SimplifyResult& lent) {
    CHECK(given.field == lent.field);
    CHECK(given.absorbed == lent.absorbed);
    CHECK(given.graph.node_values == lent.graph.node_values);
    CHECK(given.graph.node_kinds == lent.graph.node_kinds);
    CHECK(given.graph.node_vertex_offsets == lent.graph.node_vertex_offsets);
    CHECK(given.graph.node_vertices == lent.graph.node_vertices);
    CHECK(given.graph.vertex_nodes == lent.graph.vertex_nodes);
    CHECK(given.graph.arcs == lent.graph.arcs);
    CHECK(given.graph.arc_nodes == lent.graph.arc_nodes);
}

}  // namespace

TEST_CASE("The working graph's copy a wave at a time gives the same simplification", "[simplify]") {
    // The copy takes its nodes, then its arcs, a wave at a time (each wave on every thread,
    // then its areas summed and its arcs joined to their ends in order): waves of one node,
    // of a few, of many (both graphs fit in one wave of the default size), the graph lent or
    // handed over, on one thread or two: the same result bit for bit.
    struct Case {
        const char* name;
        TriangleMesh mesh;
    };
    std::vector<Case> cases;
    cases.push_back({"Vesta tile", vesta().mesh});
    cases.push_back({"noisy global Moon", noisy_global_moon()});
    for (const auto& c : cases) {
        const auto si = field::shape_index_field(c.mesh);
        const auto g = reeb::build_reeb_graph(c.mesh, si);
        REQUIRE(g.node_count() < reeb::internal::kCopyWave);
        const auto o = paper_thresholds();
        const auto simplified = [&](std::size_t wave, bool handed_over) {
            reeb::ReebGraph copy = g;
            reeb::internal::Simplifier s(c.mesh, copy, o, reeb::internal::kBigDegree, {},
                                         handed_over ? &copy : nullptr, nullptr, wave);
            if (handed_over) s.own_input(copy);
            reeb::SimplifyResult r;
            s.run({}, r);
            return r;
        };
        const auto whole =
            test::with_threads(1, [&] { return simplified(reeb::internal::kCopyWave, false); });
        for (const std::size_t wave : {std::size_t{1}, std::size_t{7}, std::size_t{4096}})
            for (const bool handed_over : {false, true})
                for (const int threads : {1, 2}) {
                    INFO(c.name << ", waves of " << wave << (handed_over ? ", handed over" : "")
                                << ", " << threads << " threads");
                    const auto r =
                        test::with_threads(threads, [&] { return simplified(wave, handed_over); });
                    check_same_result(r, whole);
                    CHECK(r.saddle_extremum == whole.saddle_extremum);
                    CHECK(r.extremum_extremum == whole.extremum_extremum);
                    CHECK(r.made_regular == whole.made_regular);
                    CHECK(r.loop_waits == whole.loop_waits);
                }
    }
}

TEST_CASE("A graph handed over gives the result of the same graph lent, plateaus and all",
          "[simplify]") {
    // Handed over, a graph with ascending vertex lists (build_reeb_graph's) gives them up once
    // its nodes are copied and the output makes them again from its vertices' nodes; a graph
    // whose lists are not ascending keeps them. Either way the result is that of the graph
    // lent (simplify(const&)), every array. Quantized noise makes plateaus: nodes of many
    // vertices.
    const auto& s = vesta();
    std::vector<float> quantized(s.si.size());
    for (std::size_t v = 0; v < quantized.size(); ++v)
        quantized[v] = std::round(s.si[v] / 8.0f) * 8.0f + float((v * 2654435761u) % 3);
    reeb::SimplifyOptions o;
    o.persistence = 10;
    o.area_ratio = 0.5;
    for (const bool ascending : {true, false}) {
        INFO((ascending ? "ascending lists" : "a list not ascending"));
        auto g = reeb::build_reeb_graph(s.mesh, quantized);
        std::size_t plateau = g.node_count();
        for (std::size_t n = 0; n < g.node_count() && plateau == g.node_count(); ++n)
            if (g.node_vertex_offsets[n + 1] - g.node_vertex_offsets[n] > 2) plateau = n;
        REQUIRE(plateau < g.node_count());
        if (!ascending)
            std::reverse(g.node_vertices.begin() + g.node_vertex_offsets[plateau],
                         g.node_vertices.begin() + g.node_vertex_offsets[plateau + 1]);
        const auto lent = reeb::simplify(s.mesh, g, o);
        // Without the rewritten field: the same graph and absorbed vertices, no field.
        reeb::SimplifyOptions unwritten = o;
        unwritten.rewrite_field = false;
        auto without = reeb::simplify(s.mesh, g, unwritten);
        CHECK(without.field.empty());
        REQUIRE(lent.field.size() == s.mesh.vertex_count());
        without.field = lent.field;
        check_same_result(without, lent);
        const auto given = reeb::simplify(s.mesh, std::move(g), o);
        check_same_result(given, lent);
        CHECK(g.node_vertices.capacity() == 0);
        CHECK(g.vertex_nodes.capacity() == 0);
    }
}

TEST_CASE(
    "A graph of a million nodes handed over, its arrays given back behind the copy, "
    "simplifies as lent",
    "[simplify]") {
    // The copy's nodes pass gives the input's node arrays back to the system in pieces of
    // 2 MiB behind it (4 MB of values at a million nodes): a piece given back before its last
    // read would read zeros and change the result. A 1200 x 1000 grid under a wave and noise.
    const auto mesh = mesh::dem_to_mesh(test::grid_dem(
        1200, 1000, [](int c, int r) { return 100 * std::sin(c * 0.01) * std::cos(r * 0.013); }));
    auto f = test::noise_field(mesh.vertex_count(), 11);
    for (std::size_t v = 0; v < f.size(); ++v) f[v] += mesh.position(v)[2];
    auto g = reeb::build_reeb_graph(mesh, f);
    REQUIRE(g.node_values.size() * sizeof(float) > 2 * detail::PagesBehind::kPiece);
    const auto o = paper_thresholds();
    const auto lent = reeb::simplify(mesh, g, o);
    const auto given = reeb::simplify(mesh, std::move(g), o);
    REQUIRE(lent.graph.node_count() > 1);
    check_same_result(given, lent);
}

TEST_CASE("A graph handed over tells its stages: the areas are read in the first only",
          "[simplify]") {
    // Stage::simplify_nodes, then simplify_arcs before the cancellations, then
    // simplify_output; what the caller does to the areas on entering the second changes
    // nothing: taken away (a mesh without areas counts 1 a vertex), or scrambled (a factor of
    // 1 to 97 a vertex: had anything read them after, the area ratios, and so the result,
    // would differ).
    const auto& s = vesta();
    const auto o = paper_thresholds();
    const auto lent = reeb::simplify(s.mesh, reeb::build_reeb_graph(s.mesh, s.si), o);
    for (const bool scramble : {false, true}) {
        INFO((scramble ? "scrambled" : "taken away"));
        TriangleMesh mesh = s.mesh;
        REQUIRE(!mesh.vertex_areas.empty());
        std::vector<float> aside;
        double last = 0;
        test::RecordingResidency memory;
        memory.on_entry[Stage::simplify_arcs] = [&] {
            CHECK(last < 0.5);  // before the cancellations
            if (!scramble) {
                aside.swap(mesh.vertex_areas);
                return;
            }
            for (std::size_t v = 0; v < mesh.vertex_areas.size(); ++v)
                mesh.vertex_areas[v] *= static_cast<float>(1 + (v * 2654435761u) % 97);
        };
        memory.on_entry[Stage::simplify_output] = [&] { CHECK(last > 0.5); };
        const auto given = reeb::simplify(
            mesh, reeb::build_reeb_graph(mesh, s.si), o,
            [&](double f, std::string_view) {
                last = f;
                return true;
            },
            memory);
        CHECK(memory.entered == std::vector<Stage>{Stage::simplify_nodes, Stage::simplify_arcs,
                                                   Stage::simplify_output});
        CHECK(mesh.vertex_areas.empty() == !scramble);
        check_same_result(given, lent);
    }
}

TEST_CASE("A graph handed over stashes the vertices' nodes until the output", "[simplify]") {
    // Stashed: the graph's vertices' nodes (from the copy of the nodes) and the working copy's
    // new numbers of the nodes (from the copy of the arcs), both taken back after the
    // cancellations, the new numbers once the working copy is freed.
    const auto& s = vesta();
    const auto o = paper_thresholds();
    const auto graph = reeb::build_reeb_graph(s.mesh, s.si);
    const auto lent = reeb::simplify(s.mesh, graph, o);
    double last = 0;
    const auto progress = [&](double f, std::string_view) {
        last = f;
        return true;
    };
    test::RecordingResidency memory;
    memory.on_entry[Stage::simplify_output] = [&] {
        CHECK(memory.stashes == 2);
        CHECK(memory.away() == 2);
        CHECK(last > 0.5);  // after the cancellations
    };
    const auto given =
        reeb::simplify(s.mesh, reeb::build_reeb_graph(s.mesh, s.si), o, progress, memory);
    CHECK(memory.taken_back == 2);
    CHECK(memory.away() == 0);
    std::multiset<std::size_t> sizes(memory.stashed_sizes.begin(), memory.stashed_sizes.end());
    CHECK(sizes == std::multiset<std::size_t>{s.mesh.vertex_count(), graph.node_count()});
    check_same_result(given, lent);
    // Given back wrong: one error, not a read out of bounds.
    test::RecordingResidency wrong;
    wrong.on_take_back = [](std::vector<std::int32_t>& v) { v.assign(3, 0); };
    CHECK_THROWS_WITH(reeb::simplify(s.mesh, reeb::build_reeb_graph(s.mesh, s.si), o, {}, wrong),
                      Catch::Contains("wrong size"));
}

TEST_CASE("The simplification's output is the same at one and two threads", "[simplify]") {
    // The output writes the vertices' nodes, flags and values in parallel over the old nodes
    // while their lists are grouped beside: every array must be the same whatever the threads,
    // with plateaus (nodes of many vertices) or without.
    const auto& s = vesta();
    std::vector<float> quantized(s.si.size());
    for (std::size_t v = 0; v < quantized.size(); ++v)
        quantized[v] = std::round(s.si[v] / 8.0f) * 8.0f + float((v * 2654435761u) % 3);
    const auto o = paper_thresholds();
    for (const std::vector<float>* f : {&s.si, &std::as_const(quantized)}) {
        const auto g = reeb::build_reeb_graph(s.mesh, *f);
        reeb::SimplifyResult one, two;
        tbb::task_arena(1).execute([&] { one = reeb::simplify(s.mesh, g, o); });
        tbb::task_arena(2).execute([&] { two = reeb::simplify(s.mesh, g, o); });
        REQUIRE(one.graph.node_count() < g.node_count());
        check_same_result(two, one);
        // Handed over (its lists made again from its vertices' nodes), the same again.
        auto given = g;
        reeb::SimplifyResult handed;
        tbb::task_arena(2).execute([&] { handed = reeb::simplify(s.mesh, std::move(given), o); });
        check_same_result(handed, one);
    }
}

TEST_CASE("The vertices absorbed are those of the nodes that did not remain (Vesta sample)",
          "[simplify]") {
    // Each remaining node is one old node, numbered anew in the order of the old ones; the
    // others' vertices joined the node that took them and are flagged absorbed. So a node's
    // vertices are all absorbed or none is, the nodes with none absorbed are as many as the
    // nodes left, and each of them is whole in a new node of its own, by increasing id. Lent
    // and handed over (the output then makes the lists again from the vertices' nodes).
    const auto& s = vesta();
    const auto g = reeb::build_reeb_graph(s.mesh, s.si);
    for (const bool handed_over : {false, true}) {
        INFO((handed_over ? "handed over" : "lent"));
        auto given = g;
        const auto r = handed_over ? reeb::simplify(s.mesh, std::move(given), paper_thresholds())
                                   : reeb::simplify(s.mesh, g, paper_thresholds());
        REQUIRE(r.absorbed.size() == s.mesh.vertex_count());
        std::size_t remaining = 0, absorbed = 0, split = 0, out_of_order = 0, empty = 0;
        std::int32_t last = -1;
        for (std::size_t n = 0; n < g.node_count(); ++n) {
            const auto first = g.node_vertex_offsets[n], end = g.node_vertex_offsets[n + 1];
            if (first >= end) {
                ++empty;
                continue;
            }
            const auto v0 = static_cast<std::size_t>(g.node_vertices[std::size_t(first)]);
            const bool gone = r.absorbed[v0] != 0;
            const std::int32_t id = r.graph.vertex_nodes[v0];
            for (auto i = first; i < end; ++i) {
                const auto v = static_cast<std::size_t>(g.node_vertices[std::size_t(i)]);
                split += (r.absorbed[v] != 0) != gone || (!gone && r.graph.vertex_nodes[v] != id);
                absorbed += gone;
            }
            if (gone) continue;
            ++remaining;
            out_of_order += id <= last;
            last = id;
        }
        CHECK(empty == 0);
        CHECK(split == 0);
        CHECK(out_of_order == 0);
        CHECK(remaining == r.graph.node_count());
        CHECK(absorbed > s.mesh.vertex_count() / 2);  // (the thresholds take most of the tile)
        CHECK(absorbed == static_cast<std::size_t>(
                              std::count(r.absorbed.begin(), r.absorbed.end(), std::uint8_t{1})));
    }
}
