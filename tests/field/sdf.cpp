#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <numeric>
#include <vector>

#include "support/cgal_reference_sdf.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/sdf.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/io/mesh_files.hpp"

using namespace terrain;
using Catch::Matchers::Contains;

namespace {

using Point = std::array<double, 3>;
using Face = std::array<std::int32_t, 3>;

TriangleMesh make_mesh(const std::vector<Point>& points, const std::vector<Face>& faces) {
    TriangleMesh mesh;
    set_positions(mesh, points);
    mesh.edit_triangles() = faces;
    finish_mesh(mesh);
    return mesh;
}

// The closed surface swept by the profile (r, z) around the z axis in `segments` steps; the
// profile starts and ends on the axis (r = 0, one pole vertex each), faces point outwards.
TriangleMesh revolve(const std::vector<std::array<double, 2>>& profile, int segments) {
    std::vector<Point> points;
    std::vector<std::vector<std::int32_t>> rings;
    for (const auto& [r, z] : profile) {
        std::vector<std::int32_t> ring;
        const int n = r == 0 ? 1 : segments;
        for (int j = 0; j < n; ++j) {
            const double phi = 2 * std::numbers::pi * j / segments;
            ring.push_back(static_cast<std::int32_t>(points.size()));
            points.push_back({r * std::cos(phi), r * std::sin(phi), z});
        }
        rings.push_back(ring);
    }
    std::vector<Face> faces;
    for (std::size_t i = 0; i + 1 < rings.size(); ++i) {
        const auto &lo = rings[i], &up = rings[i + 1];
        for (int j = 0; j < segments; ++j) {
            const int k = (j + 1) % segments;
            if (lo.size() == 1) {
                faces.push_back({lo[0], up[k], up[j]});
            } else if (up.size() == 1) {
                faces.push_back({lo[j], lo[k], up[0]});
            } else {
                faces.push_back({lo[j], lo[k], up[k]});
                faces.push_back({lo[j], up[k], up[j]});
            }
        }
    }
    return make_mesh(points, faces);
}

// A polyline through `corners`, each segment cut into pieces no longer than `step`.
std::vector<std::array<double, 2>> subdivide(const std::vector<std::array<double, 2>>& corners,
                                             double step) {
    std::vector<std::array<double, 2>> out{corners.front()};
    for (std::size_t i = 1; i < corners.size(); ++i) {
        const auto a = corners[i - 1], b = corners[i];
        const int n = std::max(1, int(std::ceil(std::hypot(b[0] - a[0], b[1] - a[1]) / step)));
        for (int k = 1; k <= n; ++k)
            out.push_back({a[0] + (b[0] - a[0]) * k / n, a[1] + (b[1] - a[1]) * k / n});
    }
    return out;
}

TriangleMesh sphere(double radius, int rings, int segments) {
    std::vector<std::array<double, 2>> profile;
    for (int i = 0; i <= rings; ++i) {
        const double theta = std::numbers::pi * i / rings;
        profile.push_back(
            {i == 0 || i == rings ? 0.0 : radius * std::sin(theta), -radius * std::cos(theta)});
    }
    return revolve(profile, segments);
}

// A rod of radius 1 (z in [0, 4]) under a drum of radius 3 (z in [4, 8]).
TriangleMesh rod_and_drum() {
    return revolve(subdivide({{0, 0}, {1, 0}, {1, 4}, {3, 4}, {3, 8}, {0, 8}}, 0.5), 24);
}

// The cube [0, 2n]^3 with an n x n grid of even integer vertices on each side (integer
// coordinates: midpoints of edges are exact).
std::pair<std::vector<Point>, std::vector<Face>> cube(int n) {
    std::map<std::array<int, 3>, std::int32_t> index;
    std::vector<Point> points;
    auto vertex = [&](std::array<int, 3> p) {
        const auto [it, added] = index.emplace(p, static_cast<std::int32_t>(points.size()));
        if (added) points.push_back({double(p[0]), double(p[1]), double(p[2])});
        return it->second;
    };
    std::vector<Face> faces;
    const int size = 2 * n;
    // Per side: the fixed axis, its value, and in-plane axes u, v with u x v outwards.
    const std::array<std::array<int, 4>, 6> sides = {{{0, 0, 2, 1},
                                                      {0, size, 1, 2},
                                                      {1, 0, 0, 2},
                                                      {1, size, 2, 0},
                                                      {2, 0, 1, 0},
                                                      {2, size, 0, 1}}};
    for (const auto& [axis, value, u, v] : sides)
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                auto at = [&](int a, int b) {
                    std::array<int, 3> p{};
                    p[axis] = value;
                    p[u] = 2 * a;
                    p[v] = 2 * b;
                    return vertex(p);
                };
                const auto p00 = at(i, j), p10 = at(i + 1, j), p11 = at(i + 1, j + 1),
                           p01 = at(i, j + 1);
                faces.push_back({p00, p10, p11});
                faces.push_back({p00, p11, p01});
            }
    return {points, faces};
}

// cube(4) with the edge a-b of its first face split at its (exact, integer) midpoint m and
// the gap closed by the zero-area face (a, b, m), the last face: still a closed 2-manifold.
std::pair<std::vector<Point>, std::vector<Face>> cube_with_sliver() {
    auto [points, faces] = cube(4);
    const auto [a, b, c] = faces[0];
    const auto m = static_cast<std::int32_t>(points.size());
    points.push_back({(points[a][0] + points[b][0]) / 2, (points[a][1] + points[b][1]) / 2,
                      (points[a][2] + points[b][2]) / 2});
    faces[0] = {a, m, c};
    faces.push_back({m, b, c});
    faces.push_back({a, b, m});
    return {points, faces};
}

double mean(const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0) / v.size();
}

// Fraction of faces whose diameters differ by more than `tolerance` of the largest.
double fraction_apart(const std::vector<double>& a, const std::vector<double>& b,
                      double tolerance) {
    REQUIRE(a.size() == b.size());
    const double scale = *std::max_element(b.begin(), b.end());
    std::size_t apart = 0;
    for (std::size_t f = 0; f < a.size(); ++f) apart += std::abs(a[f] - b[f]) > tolerance * scale;
    return double(apart) / a.size();
}

}  // namespace

TEST_CASE("SDF of a sphere: the chord along the inward normal, the same everywhere", "[sdf]") {
    const double R = 10;
    const auto mesh = sphere(R, 16, 32);
    SECTION("narrow cone: the diameter 2R") {
        field::SdfOptions narrow;
        narrow.cone_angle = 0.1;
        const auto sdf = field::shape_diameter_function(mesh, narrow);
        CHECK_FALSE(sdf.reoriented);
        CHECK(sdf.degenerate_faces == 0);
        CHECK(sdf.faces_without_value == 0);
        for (const double d : sdf.face_diameters) CHECK(d == Approx(2 * R).epsilon(0.02));
    }
    SECTION("CGAL's default cone of 120 degrees") {
        // A ray at angle t to the normal crosses the sphere in 2R cos t. CGAL's 25 rays
        // sit at tan t = tan(60 deg) i/25; the mean of those within 1.5 median absolute
        // deviations of the median is 1.5835 R. The longest rays sit just inside that
        // threshold, so on a faceted sphere a face may lose them (down to 1.545 R).
        std::vector<double> d;
        for (int i = 0; i < 25; ++i) d.push_back(2 * R / std::sqrt(1 + 3.0 * i * i / 625));
        std::sort(d.begin(), d.end());
        const double median = d[12];
        std::vector<double> dev;
        for (double x : d) dev.push_back(std::abs(x - median));
        std::sort(dev.begin(), dev.end());
        double sum = 0;
        int kept = 0;
        for (double x : d)
            if (std::abs(x - median) <= 1.5 * dev[12]) sum += x, ++kept;
        CHECK(kept == 23);
        const double expected = sum / kept;
        CHECK(expected == Approx(1.5835 * R).epsilon(1e-3));

        const auto sdf = field::shape_diameter_function(mesh);
        CHECK(mean(sdf.face_diameters) == Approx(expected).epsilon(0.03));
        for (const double x : sdf.face_diameters) CHECK(x == Approx(expected).epsilon(0.06));
        // Normalisation stretches what is left (faceting) over [0, 100]: the raw range is
        // what says the field is constant.
        CHECK(sdf.max_diameter - sdf.min_diameter < 0.05 * expected);
    }
}

TEST_CASE("SDF: a thin rod has smaller values than the thick drum on top of it", "[sdf]") {
    const auto mesh = rod_and_drum();
    const auto sdf = field::shape_diameter_function(mesh);
    REQUIRE(sdf.values.size() == mesh.vertex_count());
    float rod_max = 0, drum_min = 100;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const double z = mesh.position(v)[2];
        CHECK(sdf.values[v] >= 0);
        CHECK(sdf.values[v] <= 100);
        if (z > 1 && z < 3) rod_max = std::max(rod_max, sdf.values[v]);
        if (z > 5 && z < 7) drum_min = std::min(drum_min, sdf.values[v]);
    }
    CHECK(rod_max < drum_min);

    // Narrow cone, away from the ends: the diameter across the 24-sided prism, 2 r cos(pi/24).
    field::SdfOptions narrow;
    narrow.cone_angle = 0.1;
    const auto across = field::shape_diameter_function(mesh, narrow);
    const double rod = 2 * std::cos(std::numbers::pi / 24), drum = 3 * rod;
    std::size_t checked = 0;
    for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
        double z = 0, r = 0;
        for (auto v : mesh.triangles()[f]) {
            const auto p = mesh.position(v);
            z += p[2] / 3;
            r += std::hypot(p[0], p[1]) / 3;
        }
        if (z > 1 && z < 3 && r > 0.9) CHECK(across.face_diameters[f] == Approx(rod).epsilon(0.02));
        if (z > 5 && z < 7 && r > 2.9)
            CHECK(across.face_diameters[f] == Approx(drum).epsilon(0.02));
        checked += (z > 1 && z < 3 && r > 0.9) || (z > 5 && z < 7 && r > 2.9);
    }
    CHECK(checked >= 8 * 24);
}

TEST_CASE("SDF agrees with CGAL::sdf_values", "[sdf]") {
    struct Case {
        const char* name;
        TriangleMesh mesh;
    };
    // CGAL 5.5 skips exactly collinear faces as we do (it crashed on them before 5.0).
    const auto [points, faces] = cube_with_sliver();
    const std::vector<Case> cases = {{"sphere", sphere(1, 12, 24)},
                                     {"rod and drum", rod_and_drum()},
                                     {"cube with a zero-area face", make_mesh(points, faces)}};
    for (const auto& c : cases) {
        INFO(c.name);
        for (const bool postprocess : {true, false}) {
            INFO("postprocess " << postprocess);
            field::SdfOptions options;
            options.postprocess = postprocess;
            const auto ours = field::shape_diameter_function(c.mesh, options).face_diameters;
            auto cgal = test::cgal_sdf_face_diameters(c.mesh, options);
            // Without post-processing CGAL leaves -1 where no ray gave a value (the
            // zero-area face here); we fill those from the neighbours all the same.
            for (std::size_t f = 0; f < cgal.size(); ++f)
                if (cgal[f] == -1) {
                    CHECK(!postprocess);
                    CHECK(f == c.mesh.triangle_count() - 1);
                    cgal[f] = ours[f];
                }
            CHECK(fraction_apart(ours, cgal, 1e-9) < 0.01);
            CHECK(fraction_apart(ours, cgal, 0.02) == 0);
        }
    }
}

TEST_CASE("SDF with degenerate faces: no rays for them, values from neighbours, counted", "[sdf]") {
    auto [points, faces] = cube_with_sliver();
    const std::size_t sliver = faces.size() - 1;
    // And a face with a repeated vertex, as code (not a file reader) may produce.
    faces.push_back({faces[0][0], faces[0][0], faces[0][2]});
    const auto mesh = make_mesh(points, faces);

    field::SdfResult sdf;
    REQUIRE_NOTHROW(sdf = field::shape_diameter_function(mesh));
    CHECK(sdf.degenerate_faces == 2);
    CHECK(sdf.boundary_edges == 0);
    const auto [lo, hi] = std::minmax_element(sdf.face_diameters.begin(), sdf.face_diameters.end());
    for (const double d : sdf.face_diameters) CHECK(std::isfinite(d));
    CHECK(*lo > 0);
    for (const float v : sdf.values) {
        CHECK(std::isfinite(v));
        CHECK(v >= 0);
        CHECK(v <= 100);
    }
    // The sliver's value comes from its neighbours, in their range.
    CHECK(sdf.face_diameters[sliver] >= *lo);
    CHECK(sdf.face_diameters[sliver] <= *hi);
    // The cube's SDF is unchanged away from the split.
    const auto plain = cube(4);
    const auto reference = field::shape_diameter_function(make_mesh(plain.first, plain.second));
    CHECK(sdf.min_diameter == Approx(reference.min_diameter).epsilon(0.01));
    CHECK(sdf.max_diameter == Approx(reference.max_diameter).epsilon(0.01));
}

TEST_CASE("SDF is the same with 1 and 2 threads", "[sdf]") {
    const auto mesh = rod_and_drum();
    auto sdf = [&] { return field::shape_diameter_function(mesh); };
    const auto one = test::with_threads(1, sdf), two = test::with_threads(2, sdf);
    CHECK(one.values == two.values);
    CHECK(one.face_diameters == two.face_diameters);
}

TEST_CASE("SDF: scale-free values, inward faces, open meshes, bad options", "[sdf]") {
    const auto mesh = rod_and_drum();
    const auto sdf = field::shape_diameter_function(mesh);
    SECTION("scaling the mesh scales the diameters and keeps the values") {
        std::vector<Point> points;
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
            const auto p = mesh.position(v);
            points.push_back({p[0] * 250, p[1] * 250, p[2] * 250});
        }
        const auto scaled = field::shape_diameter_function(make_mesh(points, mesh.triangles()));
        CHECK(scaled.max_diameter == Approx(250 * sdf.max_diameter).epsilon(1e-5));
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
            CHECK(scaled.values[v] == Approx(sdf.values[v]).margin(0.01));
    }
    SECTION("faces oriented inwards: the rays are cast the other way") {
        TriangleMesh flipped = mesh;
        for (auto& t : flipped.edit_triangles()) std::swap(t[1], t[2]);
        const auto inward = field::shape_diameter_function(flipped);
        CHECK(inward.reoriented);
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
            CHECK(inward.values[v] == Approx(sdf.values[v]).margin(0.01));
    }
    SECTION("an open mesh is refused, or computed when allowed") {
        TriangleMesh open = mesh;
        open.edit_triangles().pop_back();
        CHECK_THROWS_WITH(field::shape_diameter_function(open),
                          Contains("not closed (3 boundary edges"));
        field::SdfOptions allow;
        allow.allow_open = true;
        const auto computed = field::shape_diameter_function(open, allow);
        CHECK(computed.boundary_edges == 3);
        CHECK(computed.values.size() == open.vertex_count());
    }
    SECTION("bad options") {
        field::SdfOptions bad;
        bad.rays = 0;
        CHECK_THROWS_AS(field::shape_diameter_function(mesh, bad), Error);
        bad.rays = 25;
        bad.cone_angle = std::numbers::pi;
        CHECK_THROWS_AS(field::shape_diameter_function(mesh, bad), Error);
    }
    SECTION("chosen by name") {
        field::FieldOptions options;
        options.kind = field::parse_field_kind("sdf");
        CHECK(options.kind == field::FieldKind::sdf);
        CHECK(std::string(field::to_string(options.kind)) == "sdf");
        CHECK(field::vertex_field(mesh, nullptr, options) == sdf.values);
    }
}
