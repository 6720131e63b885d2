#include <tbb/global_control.h>
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <functional>
#include <limits>

#include "terrain/field/shape_index.hpp"
#include "terrain/geo/body.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;

namespace {

// A local-grid DEM of n x n pixels of `pixel` metres, centred on (0,0), z = f(x, y).
Dem analytic(int n, double pixel, const std::function<double(double, double)>& f) {
    Dem dem;
    dem.width = dem.height = n;
    dem.transform = {-n * pixel / 2, pixel, 0, n * pixel / 2, 0, -pixel};
    dem.has_transform = true;
    dem.body = geo::body_from_crs("");
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            const auto xy = dem.map_xy(c + 0.5, r + 0.5);
            dem.values.push_back(f(xy[0], xy[1]));
        }
    return dem;
}

// Second-order derivatives of z = f(x, y) at a point: fx, fy, fxx, fxy, fyy.
using Derivatives = std::array<double, 5>;

// The exact shape index (x100) of the graph of f from its derivatives (convex positive).
double exact_shape_index(const Derivatives& d) {
    const auto [fx, fy, fxx, fxy, fyy] = d;
    const double E = 1 + fx * fx, F = fx * fy, G = 1 + fy * fy,
                 W = std::sqrt(1 + fx * fx + fy * fy);
    const double L = fxx / W, M = fxy / W, N = fyy / W, det = E * G - F * F;
    const double K = (L * N - M * M) / det, H = -(E * N - 2 * F * M + G * L) / (2 * det);
    const double root = std::sqrt(std::max(0.0, H * H - K));
    return 50.0 * (field::shape_index(H + root, H - root) + 1.0);
}

// Every vertex `margin` pixels inside the tile is within `tolerance` of the exact value.
void check_known_answer(const Dem& dem, const std::function<Derivatives(double, double)>& d,
                        const field::ShapeIndexOptions& options = {}, int margin = 3,
                        double tolerance = 1.0) {
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto field = field::shape_index_field(mesh, options);
    double worst = 0;
    std::size_t checked = 0;
    for (std::size_t v = 0; v < field.size(); ++v) {
        const int c = mesh.vertex_pixel[v] % dem.width, r = mesh.vertex_pixel[v] / dem.width;
        if (c < margin || r < margin || c >= dem.width - margin || r >= dem.height - margin)
            continue;
        const auto xy = dem.map_xy(c + 0.5, r + 0.5);
        worst = std::max(worst, std::abs(field[v] - exact_shape_index(d(xy[0], xy[1]))));
        ++checked;
    }
    REQUIRE(checked > 0);
    CHECK(worst <= tolerance);
}

const double R = 40.0;  // curvature radius in metres of the analytic surfaces

}  // namespace

TEST_CASE("shape_index of principal curvatures follows METHOD.md's convention", "[shape_index]") {
    CHECK(field::shape_index(1, 1) == Approx(1));
    CHECK(field::shape_index(-1, -1) == Approx(-1));
    CHECK(field::shape_index(1, 0) == Approx(0.5));
    CHECK(field::shape_index(0, -1) == Approx(-0.5));
    CHECK(field::shape_index(1, -1) == Approx(0).margin(1e-12));
    CHECK(field::shape_index(0, 0) == 0);
    CHECK(field::shape_index(0, 1) == Approx(0.5));  // order does not matter
}

TEST_CASE("shape index known answers on analytic DEMs", "[shape_index]") {
    const double k = 1 / R;
    SECTION("cap z = -(x^2+y^2)/2R: +1 (100) at the top") {
        const auto dem =
            analytic(31, 1.0, [&](double x, double y) { return -(x * x + y * y) * k / 2; });
        check_known_answer(dem, [&](double x, double y) {
            return Derivatives{-x * k, -y * k, -k, 0, -k};
        });
        CHECK(exact_shape_index({0, 0, -k, 0, -k}) == Approx(100));
    }
    SECTION("cup z = (x^2+y^2)/2R: -1 (0) at the bottom") {
        const auto dem =
            analytic(31, 1.0, [&](double x, double y) { return (x * x + y * y) * k / 2; });
        check_known_answer(dem, [&](double x, double y) {
            return Derivatives{x * k, y * k, k, 0, k};
        });
        CHECK(exact_shape_index({0, 0, k, 0, k}) == Approx(0).margin(1e-9));
    }
    SECTION("ridge z = -x^2/2R: +0.5 (75) everywhere") {
        const auto dem = analytic(31, 1.0, [&](double x, double) { return -x * x * k / 2; });
        check_known_answer(dem, [&](double x, double) { return Derivatives{-x * k, 0, -k, 0, 0}; });
        CHECK(exact_shape_index({0.3, 0, -k, 0, 0}) == Approx(75));
    }
    SECTION("valley z = x^2/2R: -0.5 (25) everywhere") {
        const auto dem = analytic(31, 1.0, [&](double x, double) { return x * x * k / 2; });
        check_known_answer(dem, [&](double x, double) { return Derivatives{x * k, 0, k, 0, 0}; });
        CHECK(exact_shape_index({-0.2, 0, k, 0, 0}) == Approx(25));
    }
    SECTION("symmetric saddle z = (x^2-y^2)/2R: 0 (50) at the centre") {
        const auto dem =
            analytic(31, 1.0, [&](double x, double y) { return (x * x - y * y) * k / 2; });
        check_known_answer(dem, [&](double x, double y) {
            return Derivatives{x * k, -y * k, k, 0, -k};
        });
        CHECK(exact_shape_index({0, 0, k, 0, -k}) == Approx(50));
    }
    SECTION("tilted plane: planar, 50") {
        const auto dem =
            analytic(31, 1.0, [](double x, double y) { return 0.3 * x - 0.2 * y + 5; });
        check_known_answer(
            dem,
            [](double, double) {
                return Derivatives{0.3, -0.2, 0, 0, 0};
            },
            {}, 0, 0.0);
    }
    SECTION("sphere cap on a projected grid: umbilic, +1 (100) everywhere") {
        const double r = 60;
        const auto dem =
            analytic(41, 1.0, [&](double x, double y) { return std::sqrt(r * r - x * x - y * y); });
        check_known_answer(dem, [](double, double) { return Derivatives{0, 0, -1, 0, -1}; });
    }
    SECTION("inside of a spherical bowl: -1 (0) everywhere") {
        const double r = 60;
        const auto dem = analytic(
            41, 1.0, [&](double x, double y) { return -std::sqrt(r * r - x * x - y * y); });
        check_known_answer(dem, [](double, double) { return Derivatives{0, 0, 1, 0, 1}; });
    }
}

TEST_CASE("shape index is unchanged when x, y and z are scaled together", "[shape_index]") {
    auto surface = [](double s) {
        return analytic(41, s, [s](double x, double y) {
            const double u = x / s, v = y / s;
            return s * (3 * std::sin(u * 0.3) * std::cos(v * 0.2) + 0.02 * u * v);
        });
    };
    const auto a = field::shape_index_field(mesh::dem_to_mesh(surface(1.0)));
    const auto b = field::shape_index_field(mesh::dem_to_mesh(surface(250.0)));
    REQUIRE(a.size() == b.size());
    float worst = 0;
    for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
    CHECK(worst < 0.01f);
}

TEST_CASE("shape index near edges and NoData is finite and in range", "[shape_index]") {
    Dem dem = analytic(20, 1.0, [](double x, double y) { return std::sin(x * 0.4) + y * 0.1; });
    for (int r = 5; r < 9; ++r)
        for (int c = 6; c < 10; ++c)
            dem.values[dem.index(c, r)] = std::numeric_limits<double>::quiet_NaN();
    dem.values[dem.index(19, 0)] = std::numeric_limits<double>::quiet_NaN();  // a lone corner
    const auto mesh = mesh::dem_to_mesh(dem);
    for (int rings : {1, 2, 3}) {
        field::ShapeIndexOptions options;
        options.rings = rings;
        const auto field = field::shape_index_field(mesh, options);
        std::size_t bad = 0;
        for (float v : field) bad += !(std::isfinite(v) && v >= 0 && v <= 100);
        CHECK(bad == 0);
    }
    field::ShapeIndexOptions by_radius;
    by_radius.radius = 2.5;
    const auto field = field::shape_index_field(mesh, by_radius);
    std::size_t bad = 0;
    for (float v : field) bad += !(std::isfinite(v) && v >= 0 && v <= 100);
    CHECK(bad == 0);
}

TEST_CASE("shape index with --radius gives the known answer too", "[shape_index]") {
    const double k = 1 / R;
    const auto dem =
        analytic(31, 1.0, [&](double x, double y) { return (x * x - 0.5 * y * y) * k / 2; });
    field::ShapeIndexOptions options;
    options.radius = 2.9;
    check_known_answer(
        dem,
        [&](double x, double y) {
            return Derivatives{x * k, -0.5 * y * k, k, 0, -0.5 * k};
        },
        options, 4);
}

TEST_CASE("shape index is the same whatever the thread count", "[shape_index]") {
    const auto mesh = mesh::dem_to_mesh(analytic(
        64, 2.0, [](double x, double y) { return std::sin(x * 0.1) * std::cos(y * 0.13) * 10; }));
    std::vector<float> one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = field::shape_index_field(mesh);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = field::shape_index_field(mesh);
    }
    CHECK(one == two);
}
