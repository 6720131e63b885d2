#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "support/test_meshes.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;
using field::FieldKind;

namespace {

// A 5 x 4 DEM with relief and one NoData pixel in a corner (col 0, row 0).
Dem small_dem() {
    return test::grid_dem(5, 4, [](int c, int r) {
        return c == 0 && r == 0 ? std::nan("") : 10.0 + c * c - 2.0 * r;
    });
}

}  // namespace

TEST_CASE("field names parse and print back, others are refused", "[vertex_field]") {
    for (auto kind : {FieldKind::shape_index, FieldKind::sdf, FieldKind::height})
        CHECK(field::parse_field_kind(field::to_string(kind)) == kind);
    CHECK(std::string(field::to_string(FieldKind::shape_index)) == "shape-index");
    CHECK(std::string(field::to_string(FieldKind::sdf)) == "sdf");
    CHECK(std::string(field::to_string(FieldKind::height)) == "height");
    CHECK_THROWS_AS(field::parse_field_kind("shape_index"), Error);
    CHECK_THROWS_AS(field::parse_field_kind(""), Error);
}

TEST_CASE("the height field: the DEM's value at each vertex's pixel, above the body for radii",
          "[vertex_field]") {
    auto dem = small_dem();
    const auto mesh = mesh::dem_to_mesh(dem);
    REQUIRE(mesh.vertex_count() == 19);  // 20 pixels, one NoData
    const auto heights = field::height_field(mesh, &dem);
    REQUIRE(heights.size() == mesh.vertex_count());
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const auto p = static_cast<std::size_t>(mesh.vertex_pixel[v]);
        CHECK(heights[v] == static_cast<float>(dem.values[p]));
    }

    // The same surface as radii on a 1000 m body: heights above the body again.
    Dem radii = dem;
    radii.elevation = ElevationKind::radius;
    radii.body.semi_major_axis = 1000;
    for (auto& value : radii.values) value += 1000;
    const auto above = field::height_field(mesh, &radii);
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) CHECK(above[v] == heights[v]);

    // A mesh read from a file (no DEM): z.
    const auto file_mesh = test::make_mesh({{0, 0, 5}, {1, 0, -2}, {0, 1, 0.5}}, {{0, 1, 2}});
    const auto z = field::height_field(file_mesh, nullptr);
    CHECK(z == std::vector<float>{5.0f, -2.0f, 0.5f});
}

TEST_CASE("vertex_field computes the field its options name", "[vertex_field]") {
    const auto dem = small_dem();
    const auto grid = mesh::dem_to_mesh(dem);
    field::FieldOptions options;

    double last = -1;
    const ProgressFn progress = [&](double f, std::string_view) {
        last = f;
        return true;
    };
    options.kind = FieldKind::height;
    CHECK(field::vertex_field(grid, &dem, options, progress) == field::height_field(grid, &dem));
    CHECK(last == 1.0);

    options.kind = FieldKind::shape_index;
    options.shape_index.rings = 1;
    const auto si = field::vertex_field(grid, &dem, options);
    CHECK(si == field::shape_index_field(grid, options.shape_index));
    CHECK(si != field::height_field(grid, &dem));

    // The SDF needs a closed mesh.
    const auto torus = test::torus_mesh(3, 1, 24, 12, false);
    options.kind = FieldKind::sdf;
    options.sdf.rays = 7;
    const auto sdf = field::vertex_field(torus, nullptr, options);
    CHECK(sdf == field::shape_diameter_function(torus, options.sdf).values);
    CHECK_THROWS_AS(field::vertex_field(grid, &dem, options), Error);  // open: refused
}

TEST_CASE("field_to_pixels puts each vertex's value on its pixel, NaN on NoData",
          "[vertex_field]") {
    const auto dem = small_dem();
    const auto mesh = mesh::dem_to_mesh(dem);
    std::vector<float> values(mesh.vertex_count());
    for (std::size_t v = 0; v < values.size(); ++v) values[v] = 100.0f + static_cast<float>(v);
    const auto pixels = field::field_to_pixels(mesh, dem, values);
    REQUIRE(pixels.size() == 20);
    for (std::size_t v = 0; v < values.size(); ++v)
        CHECK(pixels[static_cast<std::size_t>(mesh.vertex_pixel[v])] == values[v]);
    CHECK(std::isnan(pixels[dem.index(0, 0)]));
    std::size_t valued = 0;
    for (float p : pixels) valued += !std::isnan(p);
    CHECK(valued == mesh.vertex_count());
}
