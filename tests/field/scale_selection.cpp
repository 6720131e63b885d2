// The shape index at the radius chosen per vertex (--radius auto): known answers on bowls of
// several sizes, nested bowls, a plane, the ladder, and the same bytes on any thread count.
#include <tbb/global_control.h>
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "../../libterrain/src/field/sample_lattice.hpp"
#include "../../libterrain/src/field/shape_index_fit.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/geo/body.hpp"
#include "terrain/geo/georeference.hpp"
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

TEST_CASE("the default ladder stays within the tables on pixels longer than wide",
          "[scale_selection]") {
    // Pixels of 1 m across and 4 m down: the mean spacing is 2 m, the finer axis 1 m, so a
    // ladder of 2 to 128 mean spacings would reach 256 pixels along the rows.
    Dem dem = grid(600, [](double, double) { return 0.0; });
    dem.transform = {0, 1, 0, 0, 0, -4};
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto radii = field::default_radii(mesh);
    REQUIRE(radii.size() >= 2);
    CHECK(radii.back() <= 128.0 * 1.0001);
    // The ladder it gives is one the check of a given ladder takes, and runs as listed.
    field::ShapeIndexOptions options;
    options.auto_scale = true;
    options.radii = radii;
    CHECK(field::scale_selected_shape_index(mesh, options).radii == radii);
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

TEST_CASE("a shallow bowl keeps the contrast its curvedness is given", "[scale_selection]") {
    // A paraboloid bowl of radius a = 32 m and depth d = 0.08 a (d/D 0.04, a lunar complex
    // crater's) in a plane. At the 32 m rung its centre's curvedness is 4 d / (2 a) = 0.16
    // (docs/field.md), so the field there is 50 (1 - w), w = c^2 / (c^2 + 0.14^2) = 0.57:
    // about 22, concave; the constant 0.2 would leave it 30.5.
    constexpr double a = 32, d = 0.08 * a;
    const Selected s(160, [](double x, double y) {
        const double q = std::hypot(x - 80, y - 80) / a;
        return q < 1 ? d * (q * q - 1) : 0.0;
    });
    CHECK(s.radius_at(80, 80) == Approx(32.0).epsilon(0.02));
    const double c = 4 * d / (2 * a), w = c * c / (c * c + 0.14 * 0.14);
    CHECK(s.field_at(80, 80) == Approx(50 * (1 - w)).margin(3));
    CHECK(s.field_at(80, 80) < 26);
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

namespace {

// The curvatures for_each_curvature gives each vertex (from any thread: one slot each).
struct Fits {
    std::vector<field::PrincipalCurvatures> k;
    std::vector<std::uint8_t> fitted;
    explicit Fits(std::size_t n) : k(n), fitted(n, 0) {}
    field::detail::CurvatureBody body() {
        return [this](std::int32_t v, bool ok, const field::PrincipalCurvatures& c, double) {
            if (ok) k[std::size_t(v)] = c, fitted[std::size_t(v)] = 1;
        };
    }
    std::size_t count() const { return std::size_t(std::count(fitted.begin(), fitted.end(), 1)); }
};

// A wide rung of `radius` (the ladder's options) fitted at every vertex, and on a lattice.
std::pair<Fits, Fits> fit_all_and_lattice(const TriangleMesh& mesh, double radius, int stride) {
    field::ShapeIndexOptions options;
    options.radius = radius;
    options.skip_wide = true;
    options.disk_tile_angle = 0.4;
    std::pair<Fits, Fits> out{Fits(mesh.vertex_count()), Fits(mesh.vertex_count())};
    field::detail::for_each_curvature(mesh, options, {}, out.first.body());
    options.sample_stride = stride;
    field::detail::for_each_curvature(mesh, options, {}, out.second.body());
    return out;
}

}  // namespace

TEST_CASE("a wide rung fits the lattice's pixels alone, with every pixel's fits",
          "[scale_selection]") {
    // 61 x 45 pixels (the last column and row off the stride of 4), a NoData hole: with a
    // sample stride only the vertices of every 4th column and row and of the last ones are
    // fitted, each with the fit made at every vertex (within rounding: a tile's tables are
    // sized for the windows it fits, and their sums start where the tables do).
    auto dem = grid(61, [](double x, double y) {
        return crater(x, y, 20, 22, 9) + 0.3 * std::sin(0.7 * x + y);
    });
    dem.height = 45;
    dem.values.resize(std::size_t(61 * 45));
    for (int r = 8; r < 14; ++r)
        for (int c = 33; c < 41; ++c)
            dem.values[dem.index(c, r)] = std::numeric_limits<double>::quiet_NaN();
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto [every, sampled] = fit_all_and_lattice(mesh, 9, 4);
    std::size_t expected = 0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        if (!every.fitted[v]) continue;
        const int pixel = mesh.vertex_pixel[v], col = pixel % 61, row = pixel / 61;
        const bool on = (col % 4 == 0 || col == 60) && (row % 4 == 0 || row == 44);
        expected += on;
        CHECK(bool(sampled.fitted[v]) == on);
        if (!sampled.fitted[v]) continue;
        CHECK(sampled.k[v].k1 == Approx(every.k[v].k1).epsilon(1e-9));
        CHECK(sampled.k[v].k2 == Approx(every.k[v].k2).epsilon(1e-9));
        CHECK(sampled.k[v].noise == Approx(every.k[v].noise).epsilon(1e-9));
    }
    CHECK(sampled.count() == expected);
    CHECK(expected > 150);  // (16 x 12 lattice points, less the hole's)
}

TEST_CASE("a wide rung's lattice interpolates between the points that have a value",
          "[scale_selection]") {
    // A linear function of the pixel comes back exactly everywhere, the last column and row
    // (off the stride) included.
    const int w = 23, h = 14, stride = 4;
    const auto linear = [](int col, int row) { return float(3 + 0.5 * col + 0.25 * row); };
    field::detail::SampleLattice lattice(w, h, stride);
    for (int row = 0; row < h; ++row)
        for (int col = 0; col < w; ++col)
            lattice.set(std::int64_t(row) * w + col, linear(col, row), 2 * linear(col, row));
    for (int row = 0; row < h; ++row)
        for (int col = 0; col < w; ++col) {
            float c = 0, f = 0;
            REQUIRE(lattice.at(std::int64_t(row) * w + col, c, f));
            CHECK(c == Approx(linear(col, row)).margin(1e-5));
            CHECK(f == Approx(2 * linear(col, row)).margin(1e-5));
        }
    // A smooth field comes back closely: the cubic is within 0.4 of a wave of amplitude 20
    // over 7 and 9 pixels (0.32 measured; bilinear interpolation is off by up to 1.24 there).
    const auto wave = [](int col, int row) {
        return 50 + 20 * std::sin(col / 7.0) * std::cos(row / 9.0);
    };
    field::detail::SampleLattice smooth(w, h, stride);
    for (int row = 0; row < h; ++row)
        for (int col = 0; col < w; ++col)
            smooth.set(std::int64_t(row) * w + col, 1.0f, float(wave(col, row)));
    double worst = 0;
    for (int row = 0; row < 12; ++row)  // (the last rows' cell is narrower: linear)
        for (int col = 0; col < 20; ++col) {
            float c = 0, f = 0;
            REQUIRE(smooth.at(std::int64_t(row) * w + col, c, f));
            worst = std::max(worst, std::abs(f - wave(col, row)));
        }
    CHECK(worst < 0.4);
    // A cell with one corner's value: that value; with none, no value.
    field::detail::SampleLattice sparse(w, h, stride);
    sparse.set(std::int64_t(8) * w + 8, 7.0f, 70.0f);
    float c = 0, f = 0;
    REQUIRE(sparse.at(std::int64_t(6) * w + 6, c, f));
    CHECK(c == 7.0f);
    CHECK(f == 70.0f);
    CHECK(!sparse.at(std::int64_t(1) * w + 1, c, f));
    // The strides: every pixel below 16 pixels' radius, then an eighth of the radius.
    CHECK(field::detail::rung_stride(8) == 1);
    CHECK(field::detail::rung_stride(15.9) == 1);
    CHECK(field::detail::rung_stride(16) == 2);
    CHECK(field::detail::rung_stride(128) == 16);
    CHECK(field::detail::rung_stride(127) == 8);
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

namespace {

// Gaussian white noise of standard deviation `sigma` (Box-Muller on a fixed LCG: the same
// numbers on every machine).
struct WhiteNoise {
    std::uint64_t state = 12345;
    double uniform() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return (double(state >> 11) + 0.5) / double(1ull << 53);
    }
    double operator()(double sigma) {
        return sigma * std::sqrt(-2 * std::log(uniform())) *
               std::cos(2 * std::numbers::pi * uniform());
    }
};

}  // namespace

TEST_CASE("pixel noise: the standard deviation of white noise, none on a bowl or a slope",
          "[scale_selection]") {
    WhiteNoise noise;
    std::vector<double> values;
    for (int i = 0; i < 300 * 300; ++i) values.push_back(noise(2.5));
    std::size_t next = 0;
    const auto noisy = mesh::dem_to_mesh(
        grid(300, [&](double x, double y) { return 0.3 * x - 0.1 * y + values[next++]; }));
    CHECK(field::pixel_noise(noisy) == Approx(2.5).epsilon(0.05));
    // A quadric (here a wide bowl on a slope) is no noise at all.
    const auto smooth = mesh::dem_to_mesh(grid(300, [](double x, double y) {
        return 0.002 * ((x - 150) * (x - 150) + (y - 150) * (y - 150)) + 0.5 * x;
    }));
    CHECK(field::pixel_noise(smooth) < 1e-3);
}

TEST_CASE("the fit's noise factor is the least-squares spread of its curvedness",
          "[scale_selection]") {
    // A 2 m disk on 1 m pixels holds the 12 pixels around the centre; the 5-term fit
    // h = a u^2 + b uv + c v^2 + d u + e v over them gives, for white noise of 1 m, a
    // curvedness sqrt(2 a^2 + b^2 + 2 c^2) of spread 0.5970 1/m (the diagonal of the inverse
    // normal matrix).
    const auto mesh = mesh::dem_to_mesh(grid(21, [](double, double) { return 0.0; }));
    field::ShapeIndexOptions options;
    options.radius = 2.0;
    options.window = field::ShapeIndexWindow::disk;
    const auto k = field::principal_curvatures(mesh, options);
    CHECK(k[vertex_at(mesh, 21, 10, 10)].noise == Approx(0.5970).epsilon(0.01));
}

// The field's spread over the pixels [10, n - 10)^2 of a scale-selected field.
double spread(const Selected& s) {
    double sum = 0, sum2 = 0;
    int count = 0;
    for (int row = 10; row < s.n - 10; ++row)
        for (int col = 10; col < s.n - 10; ++col) {
            const double f = s.field_at(col, row);
            sum += f, sum2 += f * f, ++count;
        }
    const double mean = sum / count;
    return std::sqrt(sum2 / count - mean * mean);
}

TEST_CASE("white noise reads planar, a crater under it keeps its scale", "[scale_selection]") {
    WhiteNoise noise;
    std::vector<double> values;
    for (int i = 0; i < 2 * 128 * 128; ++i) values.push_back(noise(0.05));
    // The noise alone makes the 2 m rung's curvedness about 0.06, a third of the contrast
    // curvedness: kept, it speckles the plane with a spread of 12 around 50 (measured before
    // the noise was discounted); discounted, 2.4 (what remains is taken at the 4 m rung).
    std::size_t next = 0;
    const Selected plain(128, [&](double, double) { return values[next++]; });
    CHECK(spread(plain) < 4.0);
    CHECK(plain.out.pixel_noise_m == Approx(0.05).epsilon(0.15));
    // A crater under the same noise is still a cup at its own scale.
    const Selected s(128,
                     [&](double x, double y) { return crater(x, y, 64, 64, 26) + values[next++]; });
    CHECK(s.radius_at(64, 64) >= 15.9);
    CHECK(s.field_at(64, 64) < 10);
}

namespace {

// A geographic grid of the Moon as a perfect sphere: width x height pixels of `step`
// degrees, its top-left corner at (lon0, lat0), every height 0.
Dem moon_grid(int width, int height, double lon0, double lat0, double step) {
    Dem dem;
    dem.width = width;
    dem.height = height;
    dem.crs_wkt = "IAU_2015:30100";
    dem.transform = {lon0, step, 0, lat0, 0, -step};
    dem.has_transform = true;
    geo::georeference(dem);
    dem.values.assign(std::size_t(dem.width) * std::size_t(dem.height), 0.0);
    return dem;
}

// The whole Moon: width x width / 2 pixels.
Dem moon_sphere(int width) {
    return moon_grid(width, width / 2, -180, 90, 360.0 / width);
}

constexpr double kMoonRadius = 1737400;

// Heights of a paraboloid cup on moon_sphere's grid: -depth (1 - (d / a)^2) within a great-
// circle distance d < a of (lat0, 0), 0 elsewhere.
std::vector<double> cup_on_sphere(const Dem& dem, double lat0, double a, double depth) {
    const double deg = std::numbers::pi / 180, step = 360.0 / dem.width;
    std::vector<double> z(std::size_t(dem.width) * std::size_t(dem.height), 0.0);
    for (int r = 0; r < dem.height; ++r)
        for (int c = 0; c < dem.width; ++c) {
            const double lat = (90 - (r + 0.5) * step) * deg, lon = (-180 + (c + 0.5) * step) * deg;
            const double cosd = std::sin(lat) * std::sin(lat0 * deg) +
                                std::cos(lat) * std::cos(lat0 * deg) * std::cos(lon);
            const double d = kMoonRadius * std::acos(std::clamp(cosd, -1.0, 1.0));
            if (d < a)
                z[std::size_t(r) * std::size_t(dem.width) + std::size_t(c)] =
                    -depth * (1 - (d / a) * (d / a));
        }
    return z;
}

}  // namespace

TEST_CASE("the disk fit's bias on a sphere is the one the ladder takes off", "[scale_selection]") {
    const auto mesh = mesh::dem_to_mesh(moon_sphere(512));
    for (double share : {0.25, 0.5}) {
        field::ShapeIndexOptions options;
        options.radius = share * kMoonRadius;
        options.disk_tile_angle = 0.4;  // the ladder's tiles
        const auto k = field::principal_curvatures(mesh, options);
        double sum = 0;
        std::size_t count = 0;
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
            const int row = mesh.vertex_pixel[v] / 512;
            if (row < 64 || row >= 192) continue;  // within 45 degrees of the equator
            sum += k[v].k1 + k[v].k2, count += 2;
        }
        REQUIRE(count > 0);
        const double fitted = sum / double(count);
        const double seen = field::sphere_curvature_in_fit(kMoonRadius, options.radius);
        INFO("radius " << share << " r: fitted " << fitted * kMoonRadius << " / r, model "
                       << seen * kMoonRadius << " / r");
        CHECK(fitted * kMoonRadius - 1 > 0.01 * share * share);  // wider than the sphere's 1/r
        CHECK(std::abs(fitted - seen) * kMoonRadius < 0.15 * (fitted * kMoonRadius - 1));
    }
}

TEST_CASE("a window's reach is taken at a typical place of a global grid, not pixel",
          "[scale_selection]") {
    // Half of a sphere's area lies within 30 degrees of the equator, where a 1-degree grid's
    // columns are 2 pi R / 360 cos(30) apart; half its pixels lie within 45 (cos 45: the
    // narrow polar pixels would make a window reaching 128 pixels at 30 degrees reach 157).
    const auto mesh = mesh::dem_to_mesh(moon_sphere(360));
    const double column = 2 * std::numbers::pi * kMoonRadius / 360 * std::cos(std::numbers::pi / 6);
    CHECK(field::detail::typical_disk_reach(mesh, 100 * column) == Approx(100).epsilon(0.02));
}

TEST_CASE("a window's reach counts pixels on the ground, whatever the slope", "[scale_selection]") {
    // A plane rising 1 m a pixel along both axes (1 m pixels): neighbours are 1.41 m apart
    // in 3-D, 1 m on the ground, where a window counts its pixels.
    const auto slope = mesh::dem_to_mesh(grid(200, [](double x, double y) { return x + y; }));
    CHECK(field::detail::typical_disk_reach(slope, 100) == Approx(100).epsilon(0.01));
    // A tile of the Moon at 30 N, 0.01 degree pixels: its vertices lie far from the body's
    // centre (the mesh's origin holds that), the columns cos(30) of the rows apart.
    const auto mesh = mesh::dem_to_mesh(moon_grid(100, 100, 10, 30.5, 0.01));
    const double column =
        kMoonRadius * 0.01 * std::numbers::pi / 180 * std::cos(std::numbers::pi / 6);
    CHECK(field::detail::typical_disk_reach(mesh, 100 * column) == Approx(100).epsilon(0.01));
}

TEST_CASE("a body's own sphere reads planar at every rung", "[scale_selection]") {
    const auto mesh = mesh::dem_to_mesh(moon_sphere(256));
    const auto radii = field::default_radii(mesh);
    // The ladder stops at half the body's radius: a window wider is no longer a local shape.
    CHECK(radii.back() <= 0.5 * kMoonRadius);
    CHECK(2 * radii.back() > 0.5 * kMoonRadius);
    field::ShapeIndexOptions options;
    options.auto_scale = true;
    const auto out = field::scale_selected_shape_index(mesh, options);
    float worst = 0;
    for (const float f : out.field) worst = std::max(worst, std::abs(f - 50.0f));
    CHECK(worst < 0.05f);
}

TEST_CASE("near a geographic grid's poles a wide disk window is cut to the tables' reach",
          "[scale_selection]") {
    // 1 degree pixels: a window of 10 rows spans 10 / cos(latitude) columns, past the tables'
    // 128 within 4.5 degrees of a pole. Those windows are cut to 128 columns on each side
    // (their cost no longer grows towards the pole), the same cut whether the tables sum
    // them or the mesh gathers them; every vertex gets a value.
    const auto mesh = mesh::dem_to_mesh(moon_sphere(360));
    const double row = kMoonRadius * std::numbers::pi / 180;
    auto options = [&](field::ShapeIndexMethod method) {
        field::ShapeIndexOptions o;
        o.radius = 10 * row;
        o.method = method;
        return o;
    };
    const auto grid = field::shape_index_field(mesh, options(field::ShapeIndexMethod::grid));
    const auto gathered = field::shape_index_field(mesh, options(field::ShapeIndexMethod::mesh));
    REQUIRE(grid.size() == gathered.size());
    double worst = 0;
    std::size_t polar = 0, bad = 0;
    for (std::size_t v = 0; v < grid.size(); ++v) {
        bad += !(std::isfinite(grid[v]) && grid[v] >= 0 && grid[v] <= 100);
        const int r = mesh.vertex_pixel[v] / 360;
        if (r >= 5 && r < 175) continue;
        ++polar;
        worst = std::max(worst, double(std::abs(grid[v] - gathered[v])));
    }
    CHECK(bad == 0);
    REQUIRE(polar > 1000);
    CHECK(worst < 0.01);
}

TEST_CASE("the ladder reaches a crater next to a pole", "[scale_selection]") {
    // The Moon's sphere at 1 pixel a degree with a bowl of 150 km radius (5 rows) centred at
    // 80 N: its tiles' tables touch the collapsed pole row, and the ladder must still see the
    // bowl at its own scale (8 pixels or wider, not the first 2), concave, as at the equator.
    // (Its vertices' windows are held up to 16 pixels there, so the peak is seen to fall.)
    auto dem = moon_sphere(360);
    const double a = 150e3, depth = 0.1 * a;
    field::ShapeIndexOptions options;
    options.auto_scale = true;
    for (double lat0 : {80.0, 0.0}) {
        dem.values = cup_on_sphere(dem, lat0, a, depth);
        const auto mesh = mesh::dem_to_mesh(dem);
        REQUIRE(mesh.pole_rows[0] == 0);
        const auto out = field::scale_selected_shape_index(mesh, options);
        const int row = int(std::lround(89.5 - lat0)), col = 180;
        const auto v = mesh.pixel_vertex[std::size_t(row) * 360 + std::size_t(col)];
        REQUIRE(v >= 0);
        INFO("bowl at " << lat0 << " N: rung " << int(out.scale[std::size_t(v)]) << ", field "
                        << out.field[std::size_t(v)]);
        CHECK(out.scale[std::size_t(v)] >= 2);  // 8 pixels or wider, not the first 2
        CHECK(out.field[std::size_t(v)] < 25);
    }
}

TEST_CASE("a landform wider than a polar vertex's ladder reads nearly planar there",
          "[scale_selection]") {
    // A wide cup of 1 000 km radius, 400 km deep (curvedness still rising at every rung), on
    // the 1-degree Moon. At the equator it rises to the ladder's top (776 km): no peak,
    // nearly planar. At 80 N the top rungs' windows span more than the tables' 128 columns,
    // so its vertices' ladder ends at 388 km; a rise into that rung is a rise to their top
    // as well, not a peak.
    auto dem = moon_sphere(360);
    const double a = 1000e3, depth = 400e3;
    field::ShapeIndexOptions options;
    options.auto_scale = true;
    for (double lat0 : {0.0, 80.0}) {
        dem.values = cup_on_sphere(dem, lat0, a, depth);
        const auto mesh = mesh::dem_to_mesh(dem);
        const auto out = field::scale_selected_shape_index(mesh, options);
        const int row = int(std::lround(89.5 - lat0));
        const auto v = mesh.pixel_vertex[std::size_t(row) * 360 + 180];
        REQUIRE(v >= 0);
        INFO("cup at " << lat0 << " N: rung " << int(out.scale[std::size_t(v)]) << " of "
                       << out.radii.size() << ", field " << out.field[std::size_t(v)]);
        CHECK(std::abs(out.field[std::size_t(v)] - 50.0f) < 15.0f);
    }
}

TEST_CASE("a wide rung's lattice holds the seam's columns and the poles", "[scale_selection]") {
    // The 1-degree Moon with a bowl across the seam: the last column (359, off the stride of
    // 4) and both poles are fitted on the lattice, with the full fits' values; the
    // scale-selected field of a half-degree Moon, whose 16-pixel rung is on a lattice, is
    // finite and within [0, 100] at every vertex.
    auto dem = moon_sphere(360);
    dem.values = cup_on_sphere(dem, 10, 400e3, 40e3);
    // (cup_on_sphere centres the bowl at longitude 0: move it to the seam.)
    for (int r = 0; r < dem.height; ++r) {
        auto row = dem.values.begin() + std::ptrdiff_t(r) * dem.width;
        std::rotate(row, row + 180, row + dem.width);
    }
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto [every, sampled] =
        fit_all_and_lattice(mesh, 8 * kMoonRadius * std::numbers::pi / 180, 4);
    REQUIRE(sampled.count() > 80 * 45);
    std::size_t differ = 0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        if (sampled.fitted[v])
            differ += !every.fitted[v] ||
                      std::abs(sampled.k[v].k1 - every.k[v].k1) > 1e-9 * std::abs(every.k[v].k1) ||
                      std::abs(sampled.k[v].k2 - every.k[v].k2) > 1e-9 * std::abs(every.k[v].k2);
    CHECK(differ == 0);
    for (const auto pole : mesh.pole_vertices) CHECK(sampled.fitted[std::size_t(pole)]);
    CHECK(sampled.fitted[std::size_t(mesh.pixel_vertex[std::size_t(100) * 360 + 359])]);

    auto half = moon_sphere(720);
    half.values = cup_on_sphere(half, 10, 400e3, 40e3);
    const auto fine = mesh::dem_to_mesh(half);
    field::ShapeIndexOptions ladder;
    ladder.auto_scale = true;
    const auto out = field::scale_selected_shape_index(fine, ladder);
    REQUIRE(out.radii.size() >= 5);  // 2 to 32 pixels: the 16-pixel rung on a lattice
    std::size_t bad = 0;
    for (std::size_t v = 0; v < fine.vertex_count(); ++v)
        bad += !(std::isfinite(out.field[v]) && out.field[v] >= 0.0f && out.field[v] <= 100.0f &&
                 out.scale[v] < out.radii.size());
    CHECK(bad == 0);
}

TEST_CASE("the scale-selected field made by bands of rows is the whole field's on them",
          "[scale_selection]") {
    // A field split over processes or tiles: each band of rows made alone (the rows of tiles
    // around it fitted, the lattice's points around it for the wide rungs) gives its rows'
    // values and scales bit for bit. On a tile with two craters and on the half-degree Moon
    // (poles, seam, a rung on a lattice), bands cut at rows off the tiles and the lattice.
    const auto tile = mesh::dem_to_mesh(grid(128, [](double x, double y) {
        return crater(x, y, 40, 60, 7) + crater(x, y, 90, 70, 15) + 0.3 * std::sin(0.7 * x + y);
    }));
    auto moon = moon_sphere(720);
    moon.values = cup_on_sphere(moon, 10, 400e3, 40e3);
    const auto globe = mesh::dem_to_mesh(moon);
    for (const auto* mesh : {&tile, &globe}) {
        field::ShapeIndexOptions options;
        options.auto_scale = true;
        const auto whole = field::scale_selected_shape_index(*mesh, options);
        const int h = mesh->grid_height;
        const std::vector<int> cuts{0, 1, h / 3 + 1, h / 2 + 5, h - 1, h};
        std::size_t compared = 0, differ = 0;
        for (std::size_t b = 0; b + 1 < cuts.size(); ++b) {
            options.first_row = cuts[b];
            options.end_row = cuts[b + 1];
            const auto band = field::scale_selected_shape_index(*mesh, options);
            for (std::size_t v = 0; v < mesh->vertex_count(); ++v) {
                const int row = mesh->vertex_pixel[v] / mesh->grid_width;
                if (row < cuts[b] || row >= cuts[b + 1]) continue;
                ++compared;
                differ += band.field[v] != whole.field[v] || band.scale[v] != whole.scale[v];
            }
        }
        CHECK(compared == mesh->vertex_count());
        CHECK(differ == 0);
    }
    // A band's rung fits the rows of tiles around it only.
    std::size_t fitted = 0;
    field::ShapeIndexOptions one;
    one.radius = 4 * std::sqrt(mean_vertex_area(globe));
    one.first_row = 100;
    one.end_row = 101;
    field::detail::for_each_curvature(
        globe, one, {},
        [&](std::int32_t, bool, const field::PrincipalCurvatures&, double) { ++fitted; });
    CHECK(fitted > 0);
    CHECK(fitted < globe.vertex_count() / 4);
}
