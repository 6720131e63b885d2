#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>

#include "support/test_meshes.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/reeb/simplify.hpp"
#include "terrain/segment/area_range.hpp"
#include "terrain/segment/grow_regions.hpp"

using namespace terrain;

namespace {

struct Floor {
    TriangleMesh mesh;
    reeb::ReebGraph graph;  // simplified at the floor
    segment::Segmentation regions;
};

Floor at_floor(TriangleMesh mesh, const std::vector<float>& field, double floor_m2) {
    Floor f;
    reeb::SimplifyOptions o;
    o.area_ratio = reeb::area_ratio_for_area(mesh, floor_m2);
    f.graph = reeb::simplify(mesh, reeb::build_reeb_graph(mesh, field), o).graph;
    f.regions = segment::grow_regions(mesh, f.graph);
    f.mesh = std::move(mesh);
    return f;
}

// The region whose seed holds pixel (col, row)'s vertex.
std::size_t region_at(const Floor& f, int col, int row) {
    return f.regions.labels[std::size_t(row * f.mesh.grid_width + col)] - 1;
}

}  // namespace

TEST_CASE("Area range: a small bowl lives to about its own area, the deepest to the whole",
          "[segment][area_range]") {
    // Two bowls on a gently tilted plane (1 m pixels, no CRS): a wide deep one (radius 30 px)
    // and a narrow shallow one (radius 6 px); the field is the height.
    const int w = 160, h = 100;
    const auto bowl = [](double dx, double dy, double r, double depth) {
        const double q = (dx * dx + dy * dy) / (r * r);
        return q < 1 ? -depth * (1 - q) : 0.0;
    };
    const auto height = [&](int c, int r) {
        return bowl(c - 45.0, r - 50.0, 30, 20) + bowl(c - 120.0, r - 50.0, 6, 2) + 1e-3 * c +
               1e-5 * r;
    };
    auto mesh = mesh::dem_to_mesh(test::grid_dem(w, h, height));
    std::vector<float> field(mesh.vertex_count());
    for (std::size_t v = 0; v < field.size(); ++v) {
        const auto p = mesh.vertex_pixel[v];
        field[v] = float(height(int(p % w), int(p / w)));
    }
    const double floor = 20;  // m^2: both bowls are regions
    const auto f = at_floor(std::move(mesh), field, floor);
    const std::size_t big = region_at(f, 45, 50), small = region_at(f, 120, 50);
    REQUIRE(big != small);
    const double total = reeb::total_area(f.mesh);
    segment::AreaRangeOptions o;
    o.floor_m2 = floor;
    o.growth = std::numeric_limits<double>::infinity();  // the seeds alone
    auto graph = f.graph;
    const auto seeds_only = segment::seed_area_ranges(f.mesh, std::move(graph), f.regions.seeds, o);
    CHECK(graph.node_count() == 0);  // consumed
    o.growth = 2;
    graph = f.graph;
    const auto to = segment::seed_area_ranges(f.mesh, std::move(graph), f.regions.seeds, o);
    REQUIRE(to.size() == f.regions.region_count);
    // The deepest bowl holds the global minimum, which no threshold below the whole cancels.
    CHECK(seeds_only[big] == total);
    // The small bowl's floor (113 px inside its rim) is cancelled at the first doubling
    // above the area of its arc: more than its bowl, far less than the plane around.
    CHECK(seeds_only[small] > std::numbers::pi * 36);
    CHECK(seeds_only[small] <= 4 * std::numbers::pi * 36 * 2);
    // Once the small bowl is gone, the deep one heads the plane around it too (more than
    // twice its bowl): its region ends there, later than the small one's, and no range is
    // longer than its seed's.
    CHECK(to[small] == seeds_only[small]);
    CHECK(to[big] > to[small]);
    CHECK(to[big] < total);
    CHECK(to[big] >= std::numbers::pi * 900 / 2);
    for (std::size_t r = 0; r < to.size(); ++r) CHECK(to[r] <= seeds_only[r]);
    // Every range ends on the ladder (floor x 2^k) or at the whole area.
    for (const double t : to) {
        INFO(t);
        const double k = std::log2(t / floor);
        CHECK((t == total || (k >= 1 && std::abs(k - std::round(k)) < 1e-9)));
    }
}

TEST_CASE("Area range: the seeds standing at each level are a nested sweep's extrema",
          "[segment][area_range]") {
    // On the Vesta sample's shape index, with no limit on growth, the regions whose range
    // passes a threshold are the extrema of the graph simplified level by level to it.
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    auto mesh = mesh::dem_to_mesh(dem);
    const auto field = field::shape_index_field(mesh);
    const double floor = 20 * mean_vertex_area(mesh);
    const auto f = at_floor(std::move(mesh), field, floor);
    segment::AreaRangeOptions o;
    o.floor_m2 = floor;
    o.growth = std::numeric_limits<double>::infinity();
    auto graph = f.graph;
    const auto to = segment::seed_area_ranges(f.mesh, std::move(graph), f.regions.seeds, o);
    auto level = f.graph;
    std::size_t before = to.size();
    for (double t = 2 * floor; t < 64 * floor; t *= 2) {
        reeb::SimplifyOptions s;
        s.area_ratio = reeb::area_ratio_for_area(f.mesh, t);
        level = reeb::simplify(f.mesh, level, s).graph;
        const auto summary = reeb::summarize(level);
        const auto standing = std::count_if(to.begin(), to.end(), [&](double x) { return x > t; });
        INFO("threshold " << t);
        CHECK(std::size_t(standing) == summary.minima + summary.maxima);
        CHECK(std::size_t(standing) <= before);
        before = std::size_t(standing);
    }
    CHECK(before < to.size());  // the ladder did cancel seeds
}

TEST_CASE("Area range: refuses a floor or step out of range and seeds that are not extrema",
          "[segment][area_range]") {
    auto mesh = mesh::dem_to_mesh(test::grid_dem(8, 8, [](int c, int r) { return c + 0.1 * r; }));
    std::vector<float> field(mesh.vertex_count());
    for (std::size_t v = 0; v < field.size(); ++v) field[v] = float(v);
    const auto f = at_floor(std::move(mesh), field, 1);
    segment::AreaRangeOptions o;
    for (const double bad : {0.0, -1.0, std::nan("")}) {
        o.floor_m2 = bad;
        auto g = f.graph;
        CHECK_THROWS_AS(segment::seed_area_ranges(f.mesh, std::move(g), f.regions.seeds, o), Error);
    }
    o.floor_m2 = 1;
    o.growth = 0.5;
    auto h = f.graph;
    CHECK_THROWS_AS(segment::seed_area_ranges(f.mesh, std::move(h), f.regions.seeds, o), Error);
    o.growth = 2;
    o.step = 1;
    auto g = f.graph;
    CHECK_THROWS_AS(segment::seed_area_ranges(f.mesh, std::move(g), f.regions.seeds, o), Error);
    o.step = 2;
    g = f.graph;
    // A node that is not an extremum: the first regular or saddle node.
    std::int32_t regular = 0;
    while (g.is_extremum(regular)) ++regular;
    CHECK_THROWS_AS(segment::seed_area_ranges(f.mesh, std::move(g), {regular}, o), Error);
}
