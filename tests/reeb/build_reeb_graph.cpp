#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string_view>
#include <thread>
#include <tuple>

#include <tbb/task_arena.h>

#include "../../libterrain/src/reeb/contour_tree.hpp"
#include "../../libterrain/src/reeb/link_components.hpp"
#include "support/recording_residency.hpp"
#include "support/test_meshes.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/geo/georeference.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"

using namespace terrain;
using terrain::reeb::NodeKind;

namespace {

// Noise on four levels: noise_field's values (in [0, 100)) by quarters, which makes plateaus.
std::vector<float> quantized(std::vector<float> f) {
    for (float& x : f) x = std::floor(x / 25);
    return f;
}

std::vector<float> coordinate_field(const TriangleMesh& mesh, std::array<double, 3> w) {
    std::vector<float> f(mesh.vertex_count());
    for (std::size_t v = 0; v < f.size(); ++v) {
        const auto p = mesh.position(v);
        f[v] = static_cast<float>(w[0] * p[0] + w[1] * p[1] + w[2] * p[2]);
    }
    return f;
}

reeb::ReebSummary checked(const TriangleMesh& mesh, const std::vector<float>& field) {
    const auto g = reeb::build_reeb_graph(mesh, field);
    INFO(reeb::check_reeb_graph(g, field));
    REQUIRE(reeb::check_reeb_graph(g, field).empty());
    return reeb::summarize(g);
}

// Sum over critical nodes of (2 - degree): 2 (1 - loops) per connected component.
long degree_sum(const reeb::ReebGraph& g) {
    const auto inc = reeb::node_arcs(g);
    long s = 0;
    for (std::size_t n = 0; n < g.node_count(); ++n)
        if (g.is_critical(static_cast<std::int32_t>(n)))
            s += 2 - static_cast<long>(inc.degree(static_cast<std::int32_t>(n)));
    return s;
}

// The same graph, array for array (the same node numbering, arcs in the same order).
void check_same_graph(const reeb::ReebGraph& a, const reeb::ReebGraph& b) {
    CHECK(a.node_values == b.node_values);
    CHECK(a.node_kinds == b.node_kinds);
    CHECK(a.node_lower_links == b.node_lower_links);
    CHECK(a.node_upper_links == b.node_upper_links);
    CHECK(a.node_vertices == b.node_vertices);
    CHECK(a.vertex_nodes == b.vertex_nodes);
    CHECK(a.arcs == b.arcs);
    CHECK(a.arc_nodes == b.arc_nodes);
}

}  // namespace

TEST_CASE("A torus standing on its rim has one loop: min, two saddles, max", "[reeb]") {
    const auto mesh = test::torus_mesh(3, 1, 48, 24, true);
    auto f = coordinate_field(mesh, {1e-3, 2e-4, 1});
    const auto s = checked(mesh, f);
    CHECK(s.minima == 1);
    CHECK(s.maxima == 1);
    CHECK(s.saddles == 2);
    CHECK(s.arcs == 4);
    CHECK(s.loops == 1);
    CHECK(s.index_sum == Approx(0));  // Euler characteristic of the torus
}

TEST_CASE("A lying torus: level rings give two degenerate extrema and two parallel arcs",
          "[reeb]") {
    const auto mesh = test::torus_mesh(3, 1, 40, 16, false);
    const auto f = coordinate_field(mesh, {0, 0, 1});
    const auto g = reeb::build_reeb_graph(mesh, f);
    REQUIRE(reeb::check_reeb_graph(g, f).empty());
    const auto s = reeb::summarize(g);
    CHECK(s.minima == 1);
    CHECK(s.maxima == 1);
    CHECK(s.saddles == 0);
    REQUIRE(s.arcs == 2);
    CHECK(s.loops == 1);
    CHECK(g.arcs[0] == g.arcs[1]);
    // The lowest ring (40 vertices of equal z) is one node.
    const auto lo = g.arcs[0][0];
    CHECK(g.node_vertex_offsets[lo + 1] - g.node_vertex_offsets[lo] == 40);
    CHECK(g.node_upper_links[lo] == 2);
}

TEST_CASE("Closed surfaces of genus g have g loops, also under a noisy field", "[reeb]") {
    for (int genus : {0, 1, 2, 3}) {
        const auto mesh = test::plate_mesh(24, 8, genus);
        const auto topo = mesh_topology(mesh);
        REQUIRE(topo.boundary_edges == 0);
        REQUIRE(topo.euler_characteristic == 2 - 2 * genus);
        const auto height = checked(mesh, coordinate_field(mesh, {1, 0.0137, 0.00071}));
        CHECK(height.loops == static_cast<std::size_t>(genus));
        CHECK(height.index_sum == Approx(2 - 2 * genus));
        for (unsigned seed : {1u, 2u, 3u}) {
            const auto noise = test::noise_field(mesh.vertex_count(), seed + 10 * genus);
            const auto g = reeb::build_reeb_graph(mesh, noise);
            REQUIRE(reeb::check_reeb_graph(g, noise).empty());
            const auto s = reeb::summarize(g);
            CHECK(s.loops == static_cast<std::size_t>(genus));
            CHECK(s.index_sum == Approx(2 - 2 * genus));
            CHECK(degree_sum(g) == 2 - 2 * genus);
        }
    }
    const auto torus = test::torus_mesh(3, 1, 30, 12, true);
    for (unsigned seed : {4u, 5u}) {
        const auto s = checked(torus, test::noise_field(torus.vertex_count(), seed));
        CHECK(s.loops == 1);
        CHECK(s.index_sum == Approx(0));
    }
}

TEST_CASE("Disk-like DEMs give a tree, a hole in the DEM can give a loop", "[reeb]") {
    const auto dem = test::grid_dem(40, 30, [](int c, int r) { return 0.3 * c + 0.01 * r; });
    const auto mesh = mesh::dem_to_mesh(dem);
    CHECK(checked(mesh, field::height_field(mesh, &dem)).loops == 0);
    CHECK(checked(mesh, test::noise_field(mesh.vertex_count(), 7)).loops == 0);
    // A plane tilted along x around a NoData hole: contours pass on both sides of the hole.
    const auto holed = test::grid_dem(40, 30, [](int c, int r) {
        return (c >= 15 && c < 25 && r >= 10 && r < 20) ? std::nan("") : 0.3 * c + 0.01 * r;
    });
    const auto holed_mesh = mesh::dem_to_mesh(holed);
    REQUIRE(mesh_topology(holed_mesh).boundary_loops == 2);
    const auto s = checked(holed_mesh, field::height_field(holed_mesh, &holed));
    CHECK(s.loops == 1);
    CHECK(s.minima == 1);
    CHECK(s.maxima == 1);
    // Noise on the holed disk: at most one loop.
    for (unsigned seed : {8u, 9u, 10u})
        CHECK(checked(holed_mesh, test::noise_field(holed_mesh.vertex_count(), seed)).loops <= 1);
    // Two islands, a disk and a ring: two components, and the ring's loop is found.
    const auto islands = test::grid_dem(40, 30, [](int c, int r) {
        const bool gap = c >= 12 && c < 15, ring_hole = c >= 22 && c < 30 && r >= 10 && r < 20;
        return (gap || ring_hole) ? std::nan("") : 0.3 * c + 0.01 * r;
    });
    const auto islands_mesh = mesh::dem_to_mesh(islands);
    CHECK_FALSE(reeb::reeb_is_tree(islands_mesh));
    const auto t = checked(islands_mesh, field::height_field(islands_mesh, &islands));
    CHECK(t.components == 2);
    CHECK(t.loops == 1);
    // Two disks: a forest from the contour tree.
    const auto disks = test::grid_dem(
        40, 30, [](int c, int) { return (c >= 12 && c < 15) ? std::nan("") : 0.3 * c; });
    const auto disks_mesh = mesh::dem_to_mesh(disks);
    CHECK(reeb::reeb_is_tree(disks_mesh));
    const auto f = test::noise_field(disks_mesh.vertex_count(), 11);
    const auto forest =
        reeb::build_reeb_graph(disks_mesh, f, {reeb::ReebAlgorithm::contour_tree, false, nullptr});
    REQUIRE(reeb::check_reeb_graph(forest, f).empty());
    CHECK(reeb::summarize(forest).components == 2);
    CHECK(reeb::summarize(forest).loops == 0);
}

TEST_CASE("Real tiles: trees with consistent nodes and arcs", "[reeb]") {
    for (const char* name : {"vesta_hamo_tile.lbl", "mars_hirise_crop.tif"}) {
        const auto dem = io::read_dem(test::sample(name));
        const auto mesh = mesh::dem_to_mesh(dem);
        for (auto kind : {field::FieldKind::shape_index, field::FieldKind::height}) {
            field::FieldOptions options;
            options.kind = kind;
            const auto f = field::vertex_field(mesh, &dem, options);
            const auto g = reeb::build_reeb_graph(mesh, f);
            INFO(name << " " << field::to_string(kind));
            REQUIRE(reeb::check_reeb_graph(g, f).empty());
            const auto s = reeb::summarize(g);
            CHECK(s.loops == 0);
            CHECK(s.components == 1);
            CHECK(s.minima + s.maxima > 1);
            CHECK(g.memory_bytes() < 150 * mesh.vertex_count());
        }
    }
}

TEST_CASE("The closed Moon is a tree with index sum 2", "[reeb]") {
    const auto dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
    const auto mesh = mesh::dem_to_mesh(dem);
    REQUIRE(mesh_topology(mesh).boundary_edges == 0);
    for (auto kind : {field::FieldKind::shape_index, field::FieldKind::height}) {
        field::FieldOptions options;
        options.kind = kind;
        const auto f = field::vertex_field(mesh, &dem, options);
        const auto g = reeb::build_reeb_graph(mesh, f);
        REQUIRE(reeb::check_reeb_graph(g, f).empty());
        const auto s = reeb::summarize(g);
        CHECK(s.loops == 0);
        CHECK(degree_sum(g) == 2);
    }
    if (const auto ldem = test::real_data("moon_lola_ldem4/LDEM_4.LBL")) {
        const auto big = io::read_dem(*ldem);
        const auto m = mesh::dem_to_mesh(big);
        const auto f = field::height_field(m, &big);
        const auto g = reeb::build_reeb_graph(m, f);
        REQUIRE(reeb::check_reeb_graph(g, f).empty());
        CHECK(reeb::summarize(g).loops == 0);
        CHECK(degree_sum(g) == 2);
    }
}

TEST_CASE("Plateaus are single nodes: a mesa's flat top is one maximum", "[reeb]") {
    const auto dem = test::grid_dem(30, 30, [](int c, int r) {
        const double d = std::hypot(c - 14.5, r - 14.5);
        return d < 6 ? 100.0 : 100.0 - (d - 6) * 3 + 0.001 * c;
    });
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto f = field::height_field(mesh, &dem);
    const auto g = reeb::build_reeb_graph(mesh, f);
    REQUIRE(reeb::check_reeb_graph(g, f).empty());
    std::size_t top = 0;
    for (std::size_t v = 0; v < f.size(); ++v) top += f[v] == 100.0f;
    const auto n =
        g.vertex_nodes[static_cast<std::size_t>(std::find(f.begin(), f.end(), 100.0f) - f.begin())];
    CHECK(g.node_kinds[n] == NodeKind::maximum);
    CHECK(static_cast<std::size_t>(g.node_vertex_offsets[n + 1] - g.node_vertex_offsets[n]) == top);
    CHECK(reeb::summarize(g).maxima == 1);
}

TEST_CASE("Events: by value, then plateau (its lowest vertex), then vertex, in any chunking",
          "[reeb]") {
    // The events are ordered in parallel over 64 chunks of the sorted vertices: runs of equal
    // values crossing the chunks (4 levels: runs of hundreds) and many short ones (values to
    // a hundredth: runs of a few), on a grid DEM mesh.
    const auto dem = test::grid_dem(61, 47, [](int c, int r) { return 0.1 * c + 0.07 * r; });
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto noise = test::noise_field(mesh.vertex_count(), 7);
    std::vector<float> fine(noise);
    for (float& x : fine) x = std::round(x * 3) / 3;
    for (const auto& f : {quantized(noise), fine}) {
        const auto g = reeb::build_reeb_graph(mesh, f);
        REQUIRE(reeb::check_reeb_graph(g, f).empty());
        // The reference: plateaus as components of equal neighbours, their lowest vertex.
        const std::size_t n = f.size();
        std::vector<std::int32_t> low(n, -1);
        for (std::size_t v = 0; v < n; ++v) {
            if (low[v] >= 0) continue;
            std::vector<std::size_t> stack{v};
            low[v] = static_cast<std::int32_t>(v);
            while (!stack.empty()) {
                const auto u = stack.back();
                stack.pop_back();
                for (const auto w : mesh.neighbors_of(u))
                    if (low[std::size_t(w)] < 0 && f[std::size_t(w)] == f[v]) {
                        low[std::size_t(w)] = static_cast<std::int32_t>(v);
                        stack.push_back(std::size_t(w));
                    }
            }
        }
        std::vector<std::int32_t> order(n);
        std::iota(order.begin(), order.end(), 0);
        std::sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) {
            const auto key = [&](std::int32_t v) {
                return std::make_tuple(f[std::size_t(v)], low[std::size_t(v)], v);
            };
            return key(a) < key(b);
        });
        std::size_t runs = 0;
        for (std::size_t i = 1; i < n; ++i)
            runs += f[std::size_t(order[i])] == f[std::size_t(order[i - 1])];
        CHECK(runs > n / 2);
        REQUIRE(g.node_vertices == order);
        std::int32_t node = -1;
        for (std::size_t i = 0; i < n; ++i) {
            const auto v = std::size_t(order[i]);
            if (i == 0 || low[v] != low[std::size_t(order[i - 1])]) {
                ++node;
                REQUIRE(g.node_vertex_offsets[std::size_t(node)] == std::int32_t(i));
                CHECK(g.node_values[std::size_t(node)] == f[v]);
            }
            REQUIRE(g.vertex_nodes[v] == node);
        }
        CHECK(g.node_count() == std::size_t(node + 1));
        CHECK(g.node_vertex_offsets.back() == std::int32_t(n));
    }
}

TEST_CASE("The graph does not depend on the vertex order", "[reeb]") {
    const auto mesh = test::plate_mesh(16, 6, 2);
    const auto f = test::noise_field(mesh.vertex_count(), 42);
    std::vector<std::int32_t> perm(mesh.vertex_count());
    std::iota(perm.begin(), perm.end(), 0);
    std::mt19937 rng(3);
    std::shuffle(perm.begin(), perm.end(), rng);
    const auto pmesh = test::permute_mesh(mesh, perm);
    const auto pf = test::permute_field(f, perm);
    const auto a = reeb::build_reeb_graph(mesh, f);
    const auto b = reeb::build_reeb_graph(pmesh, pf);
    REQUIRE(reeb::check_reeb_graph(b, pf).empty());
    // Critical nodes by (kind, original vertex); arcs by their end vertices and regular count.
    auto describe = [](const reeb::ReebGraph& g, const std::vector<std::int32_t>* back) {
        auto vertex = [&](std::int32_t n) {
            const auto v = g.node_vertices[static_cast<std::size_t>(g.node_vertex_offsets[n])];
            return back ? (*back)[static_cast<std::size_t>(v)] : v;
        };
        std::multiset<std::tuple<int, int, int>> arcs;
        for (std::size_t k = 0; k < g.arc_count(); ++k)
            arcs.insert({vertex(g.arcs[k][0]), vertex(g.arcs[k][1]),
                         g.arc_offsets[k + 1] - g.arc_offsets[k]});
        std::set<std::pair<int, int>> nodes;
        for (std::size_t n = 0; n < g.node_count(); ++n)
            if (g.is_critical(static_cast<std::int32_t>(n)))
                nodes.insert({int(g.node_kinds[n]), vertex(static_cast<std::int32_t>(n))});
        return std::make_pair(nodes, arcs);
    };
    std::vector<std::int32_t> inverse(perm.size());
    for (std::size_t v = 0; v < perm.size(); ++v)
        inverse[static_cast<std::size_t>(perm[v])] = static_cast<std::int32_t>(v);
    CHECK(describe(a, nullptr) == describe(b, &inverse));
}

TEST_CASE("Reeb graph input errors", "[reeb]") {
    const auto mesh = test::plate_mesh(6, 4, 0);
    auto f = test::noise_field(mesh.vertex_count(), 1);
    CHECK_THROWS_AS(reeb::build_reeb_graph(mesh, std::vector<float>(3, 0.f)), Error);
    f[5] = std::nanf("");
    CHECK_THROWS_WITH(reeb::build_reeb_graph(mesh, f), Catch::Contains("NaN at vertex 5"));
    // A constant field: one node, no arcs.
    const std::vector<float> flat(mesh.vertex_count(), 50.f);
    const auto g = reeb::build_reeb_graph(mesh, flat);
    CHECK(reeb::check_reeb_graph(g, flat).empty());
    CHECK(g.node_count() == 1);
    CHECK(g.arc_count() == 0);
}

TEST_CASE("The contour tree and the sweep give the same graph on disks and spheres", "[reeb]") {
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    const auto disk = mesh::dem_to_mesh(dem);
    const auto globe_dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
    const auto sphere = mesh::dem_to_mesh(globe_dem);
    const auto holed = mesh::dem_to_mesh(test::grid_dem(20, 20, [](int c, int r) {
        return (c > 8 && c < 12 && r > 8 && r < 12) ? std::nan("") : double(c + r);
    }));
    CHECK(reeb::reeb_is_tree(disk));
    CHECK(reeb::reeb_is_tree(sphere));
    CHECK_FALSE(reeb::reeb_is_tree(holed));
    CHECK_FALSE(reeb::reeb_is_tree(test::torus_mesh(3, 1, 12, 8, true)));
    CHECK_THROWS_WITH(reeb::build_reeb_graph(holed, test::noise_field(holed.vertex_count(), 1),
                                             {reeb::ReebAlgorithm::contour_tree, false, nullptr}),
                      Catch::Contains("disks or spheres"));
    // Noise on four levels (quantized): plateaus of every shape, degenerate saddles and
    // boundary runs.
    const std::vector<std::pair<const TriangleMesh*, std::vector<float>>> cases = {
        {&disk, field::shape_index_field(disk)},
        {&disk, field::height_field(disk, &dem)},
        {&disk, quantized(test::noise_field(disk.vertex_count(), 3))},
        {&sphere, field::shape_index_field(sphere)},
        {&sphere, test::noise_field(sphere.vertex_count(), 5)},
        {&sphere, quantized(test::noise_field(sphere.vertex_count(), 7))},
    };
    for (const auto& [mesh, f] : cases) {
        const auto a =
            reeb::build_reeb_graph(*mesh, f, {reeb::ReebAlgorithm::sweep, false, nullptr});
        const auto b =
            reeb::build_reeb_graph(*mesh, f, {reeb::ReebAlgorithm::contour_tree, false, nullptr});
        REQUIRE(reeb::check_reeb_graph(b, f).empty());
        CHECK(a.node_vertices == b.node_vertices);
        CHECK(a.node_kinds == b.node_kinds);
        CHECK(a.node_lower_links == b.node_lower_links);
        CHECK(a.node_upper_links == b.node_upper_links);
        auto arcs = [](const reeb::ReebGraph& g) {
            std::set<std::vector<std::int32_t>> out;
            for (std::size_t k = 0; k < g.arc_count(); ++k) {
                std::vector<std::int32_t> arc{g.arcs[k][0], g.arcs[k][1]};
                arc.insert(arc.end(), g.arc_nodes.begin() + g.arc_offsets[k],
                           g.arc_nodes.begin() + g.arc_offsets[k + 1]);
                out.insert(arc);
            }
            return out;
        };
        CHECK(arcs(a) == arcs(b));
    }
}

TEST_CASE("A DEM mesh's Reeb graph is the same with its triangles released", "[reeb]") {
    // pipeline::compute_reeb releases a tree's triangles before the Reeb graph: the contour
    // tree then walks them again from the grid (links, plateaus' stars, loop check).
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    const auto disk = mesh::dem_to_mesh(dem);
    const auto globe_dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
    const auto sphere = mesh::dem_to_mesh(globe_dem);
    // Two fans meeting at a pinch, on a grid with a NoData column: two disks, one copy.
    const auto pinched = mesh::dem_to_mesh(test::grid_dem(9, 9, [](int c, int r) {
        return c == 4 && r != 4 ? std::nan("") : std::sin(0.9 * c) * std::cos(0.7 * r);
    }));
    REQUIRE(pinched.pinched_vertices == 1);
    const std::vector<std::pair<const TriangleMesh*, std::vector<float>>> cases = {
        {&disk, field::shape_index_field(disk)},
        {&disk, quantized(test::noise_field(disk.vertex_count(), 3))},
        {&sphere, field::height_field(sphere, &globe_dem)},
        {&sphere, quantized(test::noise_field(sphere.vertex_count(), 7))},
        {&pinched, quantized(test::noise_field(pinched.vertex_count(), 11))},
    };
    for (const auto& [mesh, f] : cases) {
        TriangleMesh released = *mesh;
        REQUIRE(reeb::reeb_is_tree(released));
        REQUIRE(released.release_triangles());
        CHECK(reeb::reeb_is_tree(released));
        const auto a = reeb::build_reeb_graph(*mesh, f);
        const auto b = reeb::build_reeb_graph(released, f);
        REQUIRE(reeb::check_reeb_graph(b, f).empty());
        check_same_graph(a, b);
    }
}

TEST_CASE("The Reeb graph tells its stages: the field is away through the contour tree", "[reeb]") {
    // pipeline::segment parks the field on disk while the contour tree runs and brings it
    // back for contour tracking, on a mesh with loops.
    const auto globe_dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
    const auto sphere = mesh::dem_to_mesh(globe_dem);
    const auto torus = test::torus_mesh(3, 1, 12, 8, true);
    for (const TriangleMesh* mesh : {&sphere, &torus}) {
        const bool tree = mesh == &sphere;
        INFO((tree ? "sphere" : "torus"));
        const auto f = quantized(test::noise_field(mesh->vertex_count(), 7));
        const auto held = reeb::build_reeb_graph(*mesh, f);
        auto field = f;
        std::vector<float> aside;
        test::RecordingResidency memory;
        // Read any further while away, the field would be out of bounds.
        memory.on_entry[Stage::reeb_links] = [&] { aside.swap(field); };
        memory.on_entry[Stage::reeb_loops] = [&] { field.swap(aside); };
        reeb::ReebOptions options;
        options.memory = &memory;
        const auto taken = reeb::build_reeb_graph(*mesh, field, options);
        std::vector<Stage> stages{Stage::reeb_events, Stage::reeb_links, Stage::reeb_sweeps,
                                  Stage::reeb_arcs};
        if (!tree) stages.push_back(Stage::reeb_loops);
        CHECK(memory.entered == stages);
        CHECK(field.empty() == tree);
        REQUIRE(reeb::check_reeb_graph(taken, f).empty());
        check_same_graph(taken, held);
    }
    // A mesh said to be a tree that has a loop: an error.
    auto torus_field = test::noise_field(torus.vertex_count(), 2);
    reeb::ReebOptions wrong;
    wrong.known_tree = true;
    CHECK_THROWS_WITH(reeb::build_reeb_graph(torus, torus_field, wrong),
                      Catch::Contains("said to be a tree"));
}

TEST_CASE("The contour tree's sweeps stash the vertex lists, nodes and values", "[reeb]") {
    // pipeline::segment parks the graph's vertex lists, their offsets, the vertices' nodes and
    // the nodes' values on disk through the join and split sweeps. A quantized field makes
    // plateaus (nodes of several vertices), whose links the sweeps read vertex by vertex:
    // from the nodes around them listed before, not from the arrays taken away.
    const auto globe_dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
    const auto sphere = mesh::dem_to_mesh(globe_dem);
    const auto torus = test::torus_mesh(3, 1, 24, 16, true);  // loops: the sweep after all
    for (const TriangleMesh* mesh : {&sphere, &torus}) {
        const auto f = quantized(test::noise_field(mesh->vertex_count(), 7));
        const auto held = reeb::build_reeb_graph(*mesh, f);
        std::size_t plateaus = 0;
        for (std::size_t n = 0; n < held.node_count(); ++n)
            plateaus += held.node_vertex_offsets[n + 1] - held.node_vertex_offsets[n] > 1;
        CHECK(plateaus > 10);
        test::RecordingResidency memory;
        memory.on_entry[Stage::reeb_sweeps] = [&] { CHECK(memory.away() == 4); };
        reeb::ReebOptions options;
        options.memory = &memory;
        const auto taken = reeb::build_reeb_graph(*mesh, f, options);
        CHECK(memory.stashes == 4);
        CHECK(memory.taken_back == 4);
        CHECK(memory.away() == 0);
        const std::size_t nv = mesh->vertex_count(), nn = held.node_count();
        std::multiset<std::size_t> sizes(memory.stashed_sizes.begin(), memory.stashed_sizes.end());
        CHECK(sizes == std::multiset<std::size_t>{nv, nv, nn + 1, nn});
        REQUIRE(reeb::check_reeb_graph(taken, f).empty());
        check_same_graph(taken, held);
    }
}

TEST_CASE("The Reeb graph's progress is monotone, on the caller's thread, whatever the threads",
          "[reeb]") {
    // The join and split sweeps run side by side; with one thread they run one after the
    // other, in either order. Reports come from the caller's thread only, from the events both
    // have passed, so the fraction never goes back.
    const auto mesh = test::plate_mesh(640, 640, 0);  // 409 600 vertices: passes of 2^18
    std::vector<float> field(mesh.vertex_count());
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> noise(0, 1);
    for (std::size_t v = 0; v < field.size(); ++v) {
        const auto p = mesh.position(v);
        field[v] = static_cast<float>(std::sin(p[0] * 0.05) + std::cos(p[1] * 0.07)) + noise(rng);
    }
    for (const int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        std::vector<double> seen;
        std::size_t sweeps = 0, elsewhere = 0;
        const auto caller = std::this_thread::get_id();
        arena.execute([&] {
            const auto g =
                reeb::build_reeb_graph(mesh, field, {}, [&](double f, std::string_view message) {
                    seen.push_back(f);
                    sweeps += message == "reeb: join and split trees" && f > 0.3 && f < 0.6;
                    elsewhere += std::this_thread::get_id() != caller;
                    return true;
                });
            CHECK(g.node_count() == mesh.vertex_count());
        });
        CAPTURE(threads);
        CHECK(std::is_sorted(seen.begin(), seen.end()));
        CHECK(sweeps >= 1);
        CHECK(elsewhere == 0);
        CHECK(seen.back() == 1.0);
    }
}

TEST_CASE("The loop check reads a whole grid from its counts, as the count by components does",
          "[reeb]") {
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    const auto globe_dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
    // The global grid without its polar caps: the seam closed, no pole: a cylinder.
    Dem band = globe_dem;
    const int skip = 20;
    band.height = globe_dem.height - 2 * skip;
    band.values.assign(globe_dem.values.begin() + std::ptrdiff_t(skip) * globe_dem.width,
                       globe_dem.values.end() - std::ptrdiff_t(skip) * globe_dem.width);
    band.transform[3] += skip * globe_dem.transform[5];
    geo::georeference(band);
    struct Case {
        const char* name;
        TriangleMesh mesh;
        bool whole, tree;
    };
    std::vector<Case> cases;
    cases.push_back({"a tile", mesh::dem_to_mesh(dem), true, true});
    cases.push_back({"the globe", mesh::dem_to_mesh(globe_dem), true, true});
    cases.push_back({"a band round the globe", mesh::dem_to_mesh(band), true, false});
    cases.push_back({"a grid with a hole",
                     mesh::dem_to_mesh(test::grid_dem(20, 20,
                                                      [](int c, int r) {
                                                          return (c > 8 && c < 12 && r > 8 &&
                                                                  r < 12)
                                                                     ? std::nan("")
                                                                     : double(c + r);
                                                      })),
                     false, false});
    cases.push_back(
        {"two disks at a pinch",
         mesh::dem_to_mesh(test::grid_dem(
             9, 9, [](int c, int r) { return c == 4 && r != 4 ? std::nan("") : double(c * r); })),
         false, true});
    cases.push_back({"a torus from a file", test::torus_mesh(3, 1, 12, 8, true), false, false});
    REQUIRE(cases[2].mesh.seam_closed);
    REQUIRE(cases[2].mesh.pole_vertices[0] < 0);
    for (const auto& c : cases) {
        INFO(c.name);
        // The counts alone: one report, at the end; the count by components reports its passes.
        int reports = 0;
        const ProgressFn count = [&](double, std::string_view) {
            ++reports;
            return true;
        };
        CHECK(reeb::internal::loop_free(c.mesh, count) == c.tree);
        CHECK((reports == 1) == c.whole);
        CHECK(reeb::internal::loop_free_by_components(c.mesh) == c.tree);
        TriangleMesh released = c.mesh;
        if (released.release_triangles()) CHECK(reeb::internal::loop_free(released) == c.tree);
    }
}

TEST_CASE("The Reeb graph is the same at one and two threads, its triangles held or released",
          "[reeb]") {
    // The events are sorted, the links counted (a released grid's triangles in bands of rows)
    // and the vertices read in parallel: the graph must not depend on the threads, nor on
    // whether the triangles are read from memory (one pass in order) or made again by rows.
    const auto globe_dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
    const auto sphere = mesh::dem_to_mesh(globe_dem);
    TriangleMesh released = sphere;
    REQUIRE(released.release_triangles());
    const std::vector<std::vector<float>> fields = {
        field::shape_index_field(sphere),                         // no plateau
        quantized(test::noise_field(sphere.vertex_count(), 13)),  // plateaus everywhere
    };
    for (const auto& f : fields) {
        const auto held = reeb::build_reeb_graph(sphere, f);
        REQUIRE(reeb::check_reeb_graph(held, f).empty());
        for (const int threads : {1, 2}) {
            CAPTURE(threads);
            reeb::ReebGraph g;
            tbb::task_arena(threads).execute([&] { g = reeb::build_reeb_graph(released, f); });
            CHECK(g.node_values == held.node_values);
            CHECK(g.node_vertex_offsets == held.node_vertex_offsets);
            CHECK(g.node_vertices == held.node_vertices);
            CHECK(g.vertex_nodes == held.vertex_nodes);
            CHECK(g.node_kinds == held.node_kinds);
            CHECK(g.node_lower_links == held.node_lower_links);
            CHECK(g.node_upper_links == held.node_upper_links);
            CHECK(g.arcs == held.arcs);
            CHECK(g.arc_offsets == held.arc_offsets);
            CHECK(g.arc_nodes == held.arc_nodes);
        }
    }
}

TEST_CASE("Link components are the same gathered in parts of the vertices", "[reeb]") {
    // Large meshes gather their stars in three passes over the triangles, each for a third of
    // the vertices; any number of parts gives the same representatives, link counts and general
    // nodes. On a disk with its triangles held and released (walked from the grid in bands of
    // rows) and on the closed Moon (poles, seam), with plateaus.
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    const auto disk = mesh::dem_to_mesh(dem);
    REQUIRE(disk.triangles_releasable());
    const auto released = [&] {
        auto m = disk;
        m.release_triangles();
        return m;
    }();
    const auto sphere = mesh::dem_to_mesh(io::read_dem(test::sample("moon_ldem1_global.tif")));
    for (const TriangleMesh* mesh : {&disk, &released, &sphere}) {
        for (const bool plateaus : {false, true}) {
            const auto f = plateaus ? quantized(test::noise_field(mesh->vertex_count(), 3))
                                    : field::shape_index_field(*mesh);
            const auto g = reeb::build_reeb_graph(*mesh, f);
            // (Each node's link counts in two bytes, those it does not count left as they were.)
            const std::size_t nn = g.node_count();
            std::vector<std::uint8_t> lower_one(nn, 7), upper_one(nn, 7);
            std::vector<char> general_one;
            const auto one =
                reeb::internal::link_components(*mesh, g, lower_one, upper_one, general_one, {}, 1);
            // Those it counts are the graph's (build_reeb_graph's), but at Reeb-regular nodes.
            bool counted = true;
            for (std::size_t n = 0; n < nn; ++n)
                if (!general_one[n] && g.node_kinds[n] != reeb::NodeKind::regular)
                    counted = counted && lower_one[n] == g.node_lower_links[n] &&
                              upper_one[n] == g.node_upper_links[n];
            CHECK(counted);
            if (plateaus) REQUIRE(std::count(general_one.begin(), general_one.end(), 1) > 0);
            for (const std::size_t parts : {2, 3, 7}) {
                INFO(parts << " parts, " << mesh->vertex_count() << " vertices");
                std::vector<std::uint8_t> lower(nn, 7), upper(nn, 7);
                std::vector<char> general;
                const auto reps =
                    reeb::internal::link_components(*mesh, g, lower, upper, general, {}, parts);
                REQUIRE(reps.size() == one.size());
                bool same = true;
                for (std::size_t n = 0; n < reps.size(); ++n)
                    same = same && reps[n].lower == one[n].lower && reps[n].upper == one[n].upper;
                CHECK(same);
                CHECK(lower == lower_one);
                CHECK(upper == upper_one);
                CHECK(general == general_one);
            }
        }
    }
}
