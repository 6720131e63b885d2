#include <catch2/catch.hpp>

#include <cmath>

#include "support/test_meshes.hpp"
#include "terrain/core/error.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/segment/lineage.hpp"

using namespace terrain;
using segment::region_lineage;

namespace {

// Five vertices in a strip of triangles; their areas are set by hand below.
TriangleMesh strip() {
    return test::make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 2, 0}},
                           {{0, 1, 2}, {1, 3, 2}, {2, 3, 4}});
}

}  // namespace

TEST_CASE("lineage of a mesh: shared vertex areas and the fractions of each parent", "[lineage]") {
    auto mesh = strip();
    mesh.vertex_areas = {1, 2, 3, 4, 5};
    // from: regions 1 = {0,1,4}, 2 = {2,3}, 3 = {} (unused id); to: 1 = {0}, 2 = {1,2,3}.
    // Vertex 4 has no label in `to`: it is shared with nothing.
    const std::vector<std::uint32_t> from{1, 1, 2, 2, 1};
    const std::vector<std::uint32_t> to{1, 2, 2, 2, 0};
    const auto lineage = region_lineage(mesh, nullptr, from, 3, to, 2);
    REQUIRE(lineage.size() == 3);

    CHECK(lineage[0].region == 1);
    CHECK(lineage[0].area_m2 == Approx(3));  // vertices 0 and 1; vertex 4 overlaps no region
    REQUIRE(lineage[0].overlaps.size() == 2);
    CHECK(lineage[0].overlaps[0].region == 1);
    CHECK(lineage[0].overlaps[0].area_m2 == Approx(1));
    CHECK(lineage[0].overlaps[0].fraction == Approx(1.0 / 3.0));
    CHECK(lineage[0].overlaps[1].region == 2);
    CHECK(lineage[0].overlaps[1].area_m2 == Approx(2));
    CHECK(lineage[0].overlaps[1].fraction == Approx(2.0 / 3.0));

    CHECK(lineage[1].region == 2);
    CHECK(lineage[1].area_m2 == Approx(7));
    REQUIRE(lineage[1].overlaps.size() == 1);
    CHECK(lineage[1].overlaps[0].region == 2);
    CHECK(lineage[1].overlaps[0].area_m2 == Approx(7));
    CHECK(lineage[1].overlaps[0].fraction == Approx(1));

    CHECK(lineage[2].region == 3);  // listed, with nothing
    CHECK(lineage[2].area_m2 == 0);
    CHECK(lineage[2].overlaps.empty());

    // Without vertex areas every vertex counts 1.
    mesh.vertex_areas.clear();
    const auto counted = region_lineage(mesh, nullptr, from, 3, to, 2);
    CHECK(counted[0].area_m2 == Approx(2));
    CHECK(counted[0].overlaps[0].fraction == Approx(0.5));
    CHECK(counted[1].area_m2 == Approx(2));
}

TEST_CASE("lineage of a DEM: pixel footprints, quadrants of two halvings", "[lineage]") {
    // 6 x 4 pixels of 2 m x 2 m: `from` splits left/right, `to` top/bottom.
    auto dem = test::grid_dem(6, 4, [](int c, int r) { return 0.1 * c + 0.2 * r; });
    dem.transform = {100, 2, 0, 50, 0, -2};
    dem.has_transform = true;
    const auto mesh = mesh::dem_to_mesh(dem);
    REQUIRE(mesh.vertex_count() == 24);
    std::vector<std::uint32_t> from(mesh.vertex_count()), to(mesh.vertex_count());
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const int p = mesh.vertex_pixel[v];
        from[v] = p % 6 < 2 ? 1 : 2;  // columns 0-1 | 2-5
        to[v] = p / 6 < 1 ? 1 : 2;    // row 0 | rows 1-3
    }
    const auto lineage = region_lineage(mesh, &dem, from, 2, to, 2);
    REQUIRE(lineage.size() == 2);
    // Region 1: 2 x 4 pixels of 4 m^2; 2 of them in row 0.
    CHECK(lineage[0].area_m2 == Approx(32));
    REQUIRE(lineage[0].overlaps.size() == 2);
    CHECK(lineage[0].overlaps[0].area_m2 == Approx(8));
    CHECK(lineage[0].overlaps[0].fraction == Approx(0.25));
    CHECK(lineage[0].overlaps[1].area_m2 == Approx(24));
    CHECK(lineage[0].overlaps[1].fraction == Approx(0.75));
    // Region 2: 4 x 4 pixels; 4 in row 0.
    CHECK(lineage[1].area_m2 == Approx(64));
    REQUIRE(lineage[1].overlaps.size() == 2);
    CHECK(lineage[1].overlaps[0].region == 1);
    CHECK(lineage[1].overlaps[0].area_m2 == Approx(16));
    CHECK(lineage[1].overlaps[1].region == 2);
    CHECK(lineage[1].overlaps[1].fraction == Approx(0.75));
    // Read the other way, the shares are the same areas.
    const auto back = region_lineage(mesh, &dem, to, 2, from, 2);
    CHECK(back[0].area_m2 == Approx(24));
    CHECK(back[0].overlaps[1].area_m2 == Approx(16));
    CHECK(back[1].overlaps[0].area_m2 == Approx(24));
}

TEST_CASE("lineage refuses labels that do not fit", "[lineage]") {
    const auto mesh = strip();
    const std::vector<std::uint32_t> ok{1, 1, 1, 1, 1};
    CHECK_THROWS_AS(region_lineage(mesh, nullptr, {1, 1, 1}, 1, ok, 1), Error);
    CHECK_THROWS_AS(region_lineage(mesh, nullptr, ok, 1, {1, 2, 1, 1, 1}, 1), Error);
    CHECK_THROWS_AS(region_lineage(mesh, nullptr, {1, 1, 3, 1, 1}, 2, ok, 1), Error);
}
