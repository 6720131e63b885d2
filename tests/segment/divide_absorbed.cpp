// The absorbed vertices divided among the regions around them (segment::divide_absorbed):
// on noisy fields the paper's growing hands most of the surface to one region; dividing keeps
// every region connected and every vertex labelled, and no region takes the surface.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>

#include "../../libterrain/src/segment/divide_absorbed_internal.hpp"
#include "support/recording_residency.hpp"
#include "support/test_meshes.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/reeb/simplify.hpp"
#include "terrain/segment/divide_absorbed.hpp"

using namespace terrain;

namespace {

// A sphere of radius 1 from an icosahedron whose faces are cut `n` x `n` times.
TriangleMesh icosphere(int n) {
    const double t = (1 + std::sqrt(5.0)) / 2;
    const std::vector<std::array<double, 3>> ico = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    const std::vector<std::array<int, 3>> faces = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    std::vector<std::array<double, 3>> points;
    std::map<std::array<long, 3>, std::int32_t> index;  // points shared along edges
    const auto point = [&](const std::array<double, 3>& p) {
        const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        const std::array<long, 3> key{std::lround(p[0] / r * 1e6), std::lround(p[1] / r * 1e6),
                                      std::lround(p[2] / r * 1e6)};
        auto [it, fresh] = index.try_emplace(key, static_cast<std::int32_t>(points.size()));
        if (fresh) points.push_back({p[0] / r, p[1] / r, p[2] / r});
        return it->second;
    };
    std::vector<std::array<std::int32_t, 3>> triangles;
    for (const auto& f : faces) {
        const auto &a = ico[f[0]], &b = ico[f[1]], &c = ico[f[2]];
        const auto at = [&](int i, int j) {  // a + i/n (b - a) + j/n (c - a)
            std::array<double, 3> p;
            for (int k = 0; k < 3; ++k) p[k] = a[k] + (b[k] - a[k]) * i / n + (c[k] - a[k]) * j / n;
            return point(p);
        };
        for (int i = 0; i < n; ++i)
            for (int j = 0; i + j < n; ++j) {
                triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
                if (i + j + 1 < n)
                    triangles.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
            }
    }
    return test::make_mesh(points, triangles);
}

struct Run {
    segment::Segmentation whole, divided;
    segment::DivideCounts counts;
};

Run segment_both(const TriangleMesh& mesh, const std::vector<float>& field) {
    reeb::SimplifyOptions o;
    o.persistence = 10;
    o.area_ratio = 0.5;
    const auto simplified = reeb::simplify(mesh, reeb::build_reeb_graph(mesh, field), o);
    Run run;
    run.whole = segment::grow_regions(mesh, simplified.graph);
    run.divided = run.whole;
    run.counts =
        segment::divide_absorbed(mesh, simplified.graph, field, simplified.absorbed, run.divided);
    return run;
}

// The largest region's share of the vertices.
double largest_share(const segment::Segmentation& s) {
    std::vector<std::size_t> count(s.region_count + 1, 0);
    for (const auto l : s.labels) ++count[l];
    return static_cast<double>(*std::max_element(count.begin(), count.end())) /
           static_cast<double>(s.labels.size());
}

// Every vertex in a region, and each region one mesh-connected piece.
void check_regions(const TriangleMesh& mesh, const segment::Segmentation& s) {
    REQUIRE(s.labels.size() == mesh.vertex_count());
    REQUIRE(std::all_of(s.labels.begin(), s.labels.end(),
                        [&](std::uint32_t l) { return l >= 1 && l <= s.region_count; }));
    const auto pieces = test::region_pieces(mesh, s.labels, s.region_count);
    for (std::uint32_t r = 1; r <= s.region_count; ++r) {
        INFO("region " << r);
        CHECK(pieces[r - 1] == 1);
    }
}

}  // namespace

TEST_CASE("Dividing absorbed vertices: no region takes a noisy sphere", "[segment][divide]") {
    // 90 252 vertices, a closed surface. (The giant grows with the mesh: on a sphere or a
    // plane of some 16 000 vertices of the same noise the paper's largest region is ~20 %.)
    const auto mesh = icosphere(95);
    REQUIRE(mesh.vertex_count() == 90252);
    const auto field = test::noise_field(mesh.vertex_count(), 7);
    const auto run = segment_both(mesh, field);
    // The paper's growing: the node that absorbed the cancellations is one region.
    CHECK(largest_share(run.whole) > 0.5);
    CHECK(run.counts.absorbed > mesh.vertex_count() / 2);
    check_regions(mesh, run.divided);
    CHECK(run.divided.region_count == run.whole.region_count);
    CHECK(run.divided.seeds == run.whole.seeds);
    CHECK(largest_share(run.divided) < 0.25);
}

TEST_CASE("Dividing absorbed vertices: no region takes a noisy plane", "[segment][divide]") {
    const auto dem = test::grid_dem(300, 300, [](int, int) { return 0.0; });
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto field = test::noise_field(mesh.vertex_count(), 3);
    const auto run = segment_both(mesh, field);
    CHECK(largest_share(run.whole) > 0.5);
    check_regions(mesh, run.divided);
    CHECK(run.divided.region_count == run.whole.region_count);
    CHECK(largest_share(run.divided) < 0.25);
}

TEST_CASE("Dividing absorbed vertices on the Vesta tile: connected, deterministic, no giant",
          "[segment][divide]") {
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto field = field::shape_index_field(mesh);
    const auto run = segment_both(mesh, field);
    check_regions(mesh, run.divided);
    CHECK(largest_share(run.whole) > 0.5);  // 74 % of the tile in one region
    CHECK(largest_share(run.divided) < 0.15);
    // Vertices that were not absorbed stay where the paper's growing put them, except those
    // cut off from their seed, which the counts name.
    std::size_t moved_kept = 0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        moved_kept += run.divided.labels[v] != run.whole.labels[v];
    CHECK(moved_kept == run.counts.relabelled);
    CHECK(run.counts.relabelled <= run.counts.absorbed + run.counts.detached);
    CHECK(segment_both(mesh, field).divided.labels == run.divided.labels);
    // Its passes over the vertices run in parallel: one thread gives the same division.
    const auto one = test::with_threads(1, [&] { return segment_both(mesh, field); });
    CHECK(one.divided.labels == run.divided.labels);
    CHECK(one.counts.relabelled == run.counts.relabelled);
    CHECK(one.counts.detached == run.counts.detached);
}

TEST_CASE("Dividing absorbed vertices in parts on the threads: the same division",
          "[segment][divide]") {
    // The flooding in order (one offer at a time) against the flooding in parts of the
    // vertices, each taking what no other part can undercut, at one and two threads; on the
    // Vesta tile (a grid, parts of rows) and on a sphere (a mesh whose vertex numbers are not
    // rows, so that each part touches many others: bumps with a little noise, and deep pits
    // that set the range, so that its steps are mostly the constant per edge length).
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    const auto tile = mesh::dem_to_mesh(dem);
    const auto sphere = icosphere(40);
    std::vector<float> bumps(sphere.vertex_count());
    for (std::size_t v = 0; v < bumps.size(); ++v) {
        const auto& p = sphere.positions()[v];
        const float noise = static_cast<float>((v * 2654435761u) % 1000) / 1000.0f;
        bumps[v] = v % 997 == 0 ? -10000.0f
                                : 30.0f * std::sin(4.0f * p[0]) * std::cos(4.0f * p[1]) + noise;
    }
    for (const auto* mesh : {&tile, &sphere}) {
        const auto field = mesh == &tile ? field::shape_index_field(tile) : bumps;
        reeb::SimplifyOptions o;
        o.persistence = 10;
        o.area_ratio = mesh == &tile ? 0.5 : 0.0;  // (the sphere's bumps and pits stay)
        const auto simplified = reeb::simplify(*mesh, reeb::build_reeb_graph(*mesh, field), o);
        const auto grown = segment::grow_regions(*mesh, simplified.graph);
        const auto divide = [&](std::size_t parts) {
            auto s = grown;
            const auto counts = segment::internal::divide_absorbed(
                *mesh, simplified.graph, field, simplified.absorbed, s, nullptr, {}, parts);
            return std::make_pair(s.labels, counts.relabelled);
        };
        const auto in_order = test::with_threads(1, [&] { return divide(1); });
        REQUIRE(in_order.second > 0);
        for (const std::size_t parts : {2, 3, 16, 64, 1000}) {
            CAPTURE(parts);
            CHECK(test::with_threads(2, [&] { return divide(parts); }) == in_order);
            CHECK(test::with_threads(1, [&] { return divide(parts); }) == in_order);
        }
        CHECK(divide(0) == in_order);
    }
}

TEST_CASE("Dividing tells its stages: the same regions with what they do not read away",
          "[segment][divide]") {
    // The caller of pipeline::segment's kind: the field and the positions come only on
    // entering the flooding, which takes the graph, the flags and the labels away; the labels
    // come back on entering the relabelling.
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    auto mesh = mesh::dem_to_mesh(dem);
    const auto field = field::shape_index_field(mesh);
    reeb::SimplifyOptions o;
    o.persistence = 10;
    o.area_ratio = 0.5;
    const auto simplified = reeb::simplify(mesh, reeb::build_reeb_graph(mesh, field), o);
    const auto grown = segment::grow_regions(mesh, simplified.graph);
    auto plain = grown;
    const auto expected =
        segment::divide_absorbed(mesh, simplified.graph, field, simplified.absorbed, plain);
    REQUIRE(expected.relabelled > 0);
    auto graph = simplified.graph;
    auto absorbed = simplified.absorbed;
    auto told = grown;
    std::vector<float> given;
    std::vector<std::uint32_t> away;
    test::RecordingResidency memory;
    memory.on_entry[Stage::flood] = [&] {
        graph = reeb::ReebGraph{};
        std::vector<std::uint8_t>().swap(absorbed);
        away.swap(told.labels);
        given = field;
        mesh::restore_positions(dem, mesh);
    };
    memory.on_entry[Stage::relabel] = [&] { told.labels.swap(away); };
    REQUIRE(mesh.release_positions());
    const auto counts =
        segment::divide_absorbed(mesh, graph, given, absorbed, told, nullptr, {}, memory);
    CHECK(memory.entered == std::vector<Stage>{Stage::flood, Stage::relabel});
    CHECK(told.labels == plain.labels);
    CHECK(counts.absorbed == expected.absorbed);
    CHECK(counts.detached == expected.detached);
    CHECK(counts.relabelled == expected.relabelled);
    // No field given on entering the flooding: the sizes disagree.
    auto again = grown;
    std::vector<float> none;
    test::RecordingResidency empty_handed;
    CHECK_THROWS_AS(segment::divide_absorbed(mesh, simplified.graph, none, simplified.absorbed,
                                             again, nullptr, {}, empty_handed),
                    Error);
}

TEST_CASE("Dividing with nothing absorbed changes nothing, mismatched sizes throw",
          "[segment][divide]") {
    const auto dem = test::grid_dem(30, 20, [](int c, int r) { return c * c + r * r; });
    const auto mesh = mesh::dem_to_mesh(dem);
    std::vector<float> field(mesh.vertex_count());
    for (std::size_t v = 0; v < field.size(); ++v) field[v] = static_cast<float>(v % 97);
    const auto simplified = reeb::simplify(mesh, reeb::build_reeb_graph(mesh, field), {});
    auto s = segment::grow_regions(mesh, simplified.graph);
    const auto before = s.labels;
    const auto counts =
        segment::divide_absorbed(mesh, simplified.graph, field, simplified.absorbed, s);
    CHECK(counts.absorbed == 0);
    CHECK(s.labels == before);
    // The stages are told all the same, once each, in order.
    test::RecordingResidency memory;
    segment::divide_absorbed(mesh, simplified.graph, field, simplified.absorbed, s, nullptr, {},
                             memory);
    CHECK(memory.entered == std::vector<Stage>{Stage::flood, Stage::relabel});
    CHECK(s.labels == before);
    std::vector<float> short_field(field.begin(), field.end() - 1);
    CHECK_THROWS_AS(
        segment::divide_absorbed(mesh, simplified.graph, short_field, simplified.absorbed, s),
        Error);
}

TEST_CASE("Dividing absorbed vertices counts the parts of regions cut off from their seeds",
          "[segment][divide]") {
    // The parts kept, found here from each seed node's vertex list: the vertices connected to
    // one of them through vertices of the same region that were not absorbed.
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto field = field::shape_index_field(mesh);
    reeb::SimplifyOptions o;
    o.persistence = 10;
    o.area_ratio = 0.5;
    const auto simplified = reeb::simplify(mesh, reeb::build_reeb_graph(mesh, field), o);
    const auto& g = simplified.graph;
    const auto grown = segment::grow_regions(mesh, g);
    const std::size_t n = mesh.vertex_count();
    const auto left = [&](std::size_t v) { return simplified.absorbed[v] != 0; };
    std::vector<char> kept(n, 0);
    std::vector<std::size_t> stack;
    for (std::size_t r = 0; r < grown.seeds.size(); ++r) {
        const auto s = static_cast<std::size_t>(grown.seeds[r]);
        for (auto i = g.node_vertex_offsets[s]; i < g.node_vertex_offsets[s + 1]; ++i) {
            const auto v = static_cast<std::size_t>(g.node_vertices[static_cast<std::size_t>(i)]);
            if (left(v) || grown.labels[v] != r + 1 || kept[v]) continue;
            kept[v] = 1;
            stack.push_back(v);
        }
        while (!stack.empty()) {
            const std::size_t v = stack.back();
            stack.pop_back();
            for (const auto w : mesh.neighbors_of(v)) {
                const auto u = static_cast<std::size_t>(w);
                if (left(u) || grown.labels[u] != r + 1 || kept[u]) continue;
                kept[u] = 1;
                stack.push_back(u);
            }
        }
    }
    std::size_t detached = 0;
    for (std::size_t v = 0; v < n; ++v) detached += !left(v) && !kept[v];
    auto divided = grown;
    const auto counts = segment::divide_absorbed(mesh, g, field, simplified.absorbed, divided);
    REQUIRE(detached > 0);  // the tile has such parts
    CHECK(counts.detached == detached);
    // A kept vertex stays in its region.
    for (std::size_t v = 0; v < n; ++v)
        if (kept[v] && divided.labels[v] != grown.labels[v]) FAIL("kept vertex " << v << " moved");
}
