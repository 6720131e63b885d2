// The shape index at the radius chosen per vertex (--radius auto): known answers on bowls of
// several sizes, nested bowls, a plane, the ladder, and the same bytes on any thread count.
#include <tbb/global_control.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <vector>

#include "terrain/core/error.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/geo/body.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;

namespace {

// A local-grid DEM of n x n pixels of 1 m, (0,0) at its top-left corner, z = f(col, row) at
// pixel centres.
Dem grid(int n, const std::function<double(double, double)>& f) {
    Dem dem;
    dem.width = dem.height = n;
    dem.transform = {0, 1, 0, 0, 0, -1};
    dem.has_transform = true;
    dem.body = geo::body_from_crs("");
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) dem.values.push_back(f(c + 0.5, r + 0.5));
    return dem;
}

// A fresh simple crater of radius `a` centred at (cx, cy): a paraboloid bowl 0.4 a deep
// (depth over diameter 0.2) under a rim 0.08 a high that falls off outside.
double crater(double x, double y, double cx, double cy, double a) {
    const double s = std::hypot(x - cx, y - cy) / a, rim = 0.08 * a;
    return s < 1 ? 0.4 * a * (s * s - 1) + rim : rim * std::exp(-6 * (s - 1));
}

std::size_t vertex_at(const TriangleMesh& mesh, int n, int col, int row) {
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        if (mesh.vertex_pixel[v] == row * n + col) return v;
    FAIL("no vertex at that pixel");
    return 0;
}

// The scale-selected field of an n x n DEM, read back at pixels.
struct Selected {
    int n;
    TriangleMesh mesh;
    field::ScaleSelectedField out;

    Selected(int size, const std::function<double(double, double)>& f)
        : n(size), mesh(mesh::dem_to_mesh(grid(size, f))) {
        field::ShapeIndexOptions options;
        options.auto_scale = true;
        out = field::scale_selected_shape_index(mesh, options);
    }
    double radius_at(int col, int row) const {
        return out.radii[out.scale[vertex_at(mesh, n, col, row)]];
    }
    float field_at(int col, int row) const { return out.field[vertex_at(mesh, n, col, row)]; }
};

}  // namespace

TEST_CASE("the ladder: 2 to 128 pixels, below half the grid", "[scale_selection]") {
    const auto mesh = mesh::dem_to_mesh(grid(100, [](double, double) { return 0.0; }));
    const auto radii = field::default_radii(mesh);
    REQUIRE(radii.size() == 5);  // 2, 4, 8, 16, 32: 64 is over 100 / 2
    CHECK(radii.front() == Approx(2.0).epsilon(0.02));
    CHECK(radii.back() == Approx(32.0).epsilon(0.02));
    CHECK(field::default_radii(mesh::dem_to_mesh(grid(600, [](double, double) {
              return 0.0;
          }))).size() == 7);  // up to 128
    TriangleMesh file_mesh = mesh;
    file_mesh.grid_width = file_mesh.grid_height = 0;
    CHECK_THROWS_AS(field::default_radii(file_mesh), Error);
}

TEST_CASE("each crater is seen at its own radius, the plane reads planar", "[scale_selection]") {
    const Selected s(192, [](double x, double y) {
        return crater(x, y, 48, 48, 5) + crater(x, y, 120, 120, 26);
    });
    REQUIRE(s.out.radii.size() == 6);  // 2 to 64 m
    // The small crater's centre takes a radius near its own (5 m: the 4 or 8 m rung), the
    // large one's near its own (26 m: the 16 or 32 m rung); both read as cups.
    CHECK(s.radius_at(48, 48) >= 3.9);
    CHECK(s.radius_at(48, 48) <= 8.1);
    CHECK(s.radius_at(120, 120) >= 15.9);
    CHECK(s.field_at(48, 48) < 10);
    CHECK(s.field_at(120, 120) < 10);
    // Halfway to the large crater's rim, still its bowl at its scale.
    CHECK(s.field_at(133, 120) < 25);
    CHECK(s.radius_at(133, 120) >= 15.9);
    // Far from both, the plane: no landform at any scale, exactly planar.
    CHECK(s.field_at(175, 20) == 50.0f);
}

TEST_CASE("a small crater on a large crater's floor keeps its own scale", "[scale_selection]") {
    const Selected s(
        192, [](double x, double y) { return crater(x, y, 96, 96, 40) + crater(x, y, 96, 96, 6); });
    CHECK(s.radius_at(96, 96) <= 8.1);    // the small crater
    CHECK(s.radius_at(96, 116) >= 15.9);  // the large floor around it
    CHECK(s.field_at(96, 96) < 10);
    CHECK(s.field_at(96, 116) < 20);
}

TEST_CASE("the scale-selected field is the same on any thread count", "[scale_selection]") {
    const int n = 128;
    const auto dem = grid(n, [](double x, double y) {
        return crater(x, y, 40, 60, 7) + crater(x, y, 90, 70, 15) + 0.3 * std::sin(0.7 * x + y);
    });
    const auto mesh = mesh::dem_to_mesh(dem);
    field::ShapeIndexOptions options;
    options.auto_scale = true;
    field::ScaleSelectedField one;
    {
        tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
        one = field::scale_selected_shape_index(mesh, options);
    }
    const auto many = field::scale_selected_shape_index(mesh, options);
    CHECK(one.field == many.field);
    CHECK(one.scale == many.scale);
    // shape_index_field gives the same values with auto_scale.
    CHECK(field::shape_index_field(mesh, options) == many.field);
}

TEST_CASE("the ladder's field is the same with the normals made by bands of rows",
          "[scale_selection]") {
    // With the triangles freed the grid method makes its normals a row of tiles at a time
    // (band_normals); with them held, the whole mesh's at once: the same bits either way.
    const int n = 160;
    const auto dem = grid(n, [](double x, double y) {
        return crater(x, y, 40, 60, 7) + crater(x, y, 100, 90, 22) + 0.3 * std::sin(0.7 * x + y);
    });
    const auto held = mesh::dem_to_mesh(dem);
    auto freed = held;
    REQUIRE(freed.release_triangles());
    field::ShapeIndexOptions options;
    options.auto_scale = true;
    const auto whole = field::scale_selected_shape_index(held, options);
    const auto bands = field::scale_selected_shape_index(freed, options);
    CHECK(whole.field == bands.field);
    CHECK(whole.scale == bands.scale);
}

TEST_CASE("a ladder of radii is checked", "[scale_selection]") {
    const auto mesh = mesh::dem_to_mesh(grid(64, [](double, double) { return 0.0; }));
    field::ShapeIndexOptions options;
    options.auto_scale = true;
    options.radii = {4, 2};
    CHECK_THROWS_AS(field::scale_selected_shape_index(mesh, options), Error);
    options.radii = {2, -1};
    CHECK_THROWS_AS(field::scale_selected_shape_index(mesh, options), Error);
    options.radii = {2, 4, 8};
    CHECK(field::scale_selected_shape_index(mesh, options).radii == options.radii);
}
