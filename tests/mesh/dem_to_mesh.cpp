#include <tbb/global_control.h>
#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/UTMUPS.hpp>
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numbers>

#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/geo/georeference.hpp"
#include "terrain/internal/mesh/grid_triangles.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// A local-grid DEM (no CRS) of w x h pixels of `pixel` metres, values from f(col,row).
template <class F>
Dem grid_dem(int w, int h, double pixel, F f) {
    Dem dem;
    dem.width = w;
    dem.height = h;
    dem.transform = {0, pixel, 0, 0, 0, -pixel};
    dem.has_transform = true;
    geo::georeference(dem);
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) dem.values.push_back(f(c, r));
    return dem;
}

double total_area(const TriangleMesh& m) {
    double a = 0;
    for (float v : m.vertex_areas) a += v;
    return a;
}

// Signed volume enclosed (divergence theorem); positive when triangles face outwards.
double signed_volume(const TriangleMesh& m) {
    double vol = 0;
    for (const auto& t : m.triangles()) {
        const auto a = m.position(t[0]), b = m.position(t[1]), c = m.position(t[2]);
        vol += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
               a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return vol / 6.0;
}

void check_manifold(const TriangleMesh& mesh) {
    // Every edge in at most two triangles, each direction at most once (consistent
    // orientation); every vertex link a single fan.
    std::map<std::pair<int, int>, int> directed;
    for (const auto& t : mesh.triangles())
        for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
    std::size_t repeated = 0;
    for (const auto& [edge, count] : directed) repeated += count != 1;
    CHECK(repeated == 0);
    TriangleMesh copy = mesh;
    CHECK(split_pinched_vertices(copy) == 0);
}

}  // namespace

TEST_CASE("dem_to_mesh: counts on a full grid", "[mesh]") {
    const Dem dem = grid_dem(4, 3, 10.0, [](int c, int r) { return c * 1.0 + r * 0.5; });
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto topo = mesh_topology(mesh);
    CHECK(topo.vertices == 12);
    CHECK(topo.faces == 12);
    CHECK(topo.boundary_edges == 10);
    CHECK(topo.boundary_loops == 1);
    CHECK(topo.euler_characteristic == 1);
    CHECK(mesh.frame == MeshFrame::map);
    check_manifold(mesh);
    // Every vertex keeps its pixel.
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const int col = mesh.vertex_pixel[v] % 4, row = mesh.vertex_pixel[v] / 4;
        const auto p = mesh.position(v);
        CHECK(p[0] == Approx(10.0 * (col + 0.5)));
        CHECK(p[1] == Approx(-10.0 * (row + 0.5)));
        CHECK(p[2] == Approx(col * 1.0 + row * 0.5));
    }
    // Triangles face up (counter-clockwise seen from +z).
    for (const auto& t : mesh.triangles()) {
        const auto a = mesh.position(t[0]), b = mesh.position(t[1]), c = mesh.position(t[2]);
        CHECK((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0);
    }
}

TEST_CASE("dem_to_mesh: a NoData hole makes an annulus", "[mesh]") {
    const Dem dem = grid_dem(5, 5, 1.0, [](int c, int r) { return c == 2 && r == 2 ? kNaN : 0.0; });
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto topo = mesh_topology(mesh);
    CHECK(topo.vertices == 24);
    CHECK(topo.faces == 28);  // 12 full blocks x 2 + 4 blocks of three pixels
    CHECK(topo.boundary_loops == 2);
    CHECK(topo.euler_characteristic == 0);
    check_manifold(mesh);
    const auto p2v = mesh::pixel_to_vertex(mesh, dem);
    CHECK(p2v[12] == -1);
    CHECK(p2v[0] == 0);
}

TEST_CASE("dem_to_mesh: the shorter 3-D diagonal splits a block", "[mesh]") {
    // A high top-right corner makes the top-right/bottom-left diagonal the longer one.
    const Dem dem = grid_dem(2, 2, 1.0, [](int c, int r) { return c == 1 && r == 0 ? 5.0 : 0.0; });
    const auto mesh = mesh::dem_to_mesh(dem);
    REQUIRE(mesh.triangle_count() == 2);
    for (const auto& t : mesh.triangles()) {
        const bool has_00 = std::find(t.begin(), t.end(), 0) != t.end();
        const bool has_11 = std::find(t.begin(), t.end(), 3) != t.end();
        CHECK((has_00 && has_11));
    }
    const Dem other = grid_dem(2, 2, 1.0, [](int c, int r) { return c + r == 0 ? 5.0 : 0.0; });
    const auto other_mesh = mesh::dem_to_mesh(other);
    for (const auto& t : other_mesh.triangles()) {
        const bool has_10 = std::find(t.begin(), t.end(), 1) != t.end();
        const bool has_01 = std::find(t.begin(), t.end(), 2) != t.end();
        CHECK((has_10 && has_01));
    }
}

TEST_CASE("dem_to_mesh: a pinched vertex is split, one copy per fan", "[mesh]") {
    // V . V / V V V / V . V: the centre's left and right fans meet only at it.
    const Dem dem = grid_dem(3, 3, 1.0, [](int c, int r) { return c == 1 && r != 1 ? kNaN : 1.0; });
    const auto mesh = mesh::dem_to_mesh(dem);
    CHECK(mesh.pinched_vertices == 1);
    const auto topo = mesh_topology(mesh);
    CHECK(topo.vertices == 8);
    CHECK(topo.faces == 4);
    CHECK(topo.components == 2);
    CHECK(topo.euler_characteristic == 2);
    check_manifold(mesh);
    // Both copies keep the centre pixel; the pixel maps back to the first.
    CHECK(mesh.vertex_pixel[7] == 4);
    CHECK(mesh::pixel_to_vertex(mesh, dem)[4] < 7);
}

TEST_CASE("dem_to_mesh: isolated pixels are left out and counted", "[mesh]") {
    const Dem dem = grid_dem(4, 4, 1.0, [](int c, int r) {
        if (c == 3 && r == 3) return 1.0;  // alone in a corner
        return c < 2 && r < 2 ? 0.0 : kNaN;
    });
    const auto mesh = mesh::dem_to_mesh(dem);
    CHECK(mesh.isolated_vertices == 1);
    CHECK(mesh.vertex_count() == 4);
}

TEST_CASE("dem_to_mesh: the global LOLA Moon is a closed sphere", "[mesh]") {
    const Dem dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto topo = mesh_topology(mesh);
    CHECK(mesh.frame == MeshFrame::body);
    CHECK(mesh.seam_closed);
    CHECK(mesh.pole_rows[0] == 0);
    CHECK(mesh.pole_rows[1] == 179);
    CHECK(topo.boundary_edges == 0);
    CHECK(topo.euler_characteristic == 2);
    CHECK(topo.vertices == 360 * 178 + 2);
    check_manifold(mesh);
    const double r = 1737400, pi = std::numbers::pi;
    CHECK(total_area(mesh) == Approx(4 * pi * r * r).epsilon(0.01));
    CHECK(signed_volume(mesh) == Approx(4.0 / 3.0 * pi * r * r * r).epsilon(0.01));
    // Every valid pixel maps to a vertex, the pole rows to their pole.
    const auto p2v = mesh::pixel_to_vertex(mesh, dem);
    CHECK(std::count(p2v.begin(), p2v.end(), -1) == 0);
    CHECK(p2v[5] == mesh.pole_vertices[0]);
}

TEST_CASE("dem_to_mesh: LDEM_4 closes, area within 1% of 4 pi R^2", "[mesh][real_data]") {
    const auto path = test::real_data("moon_lola_ldem4/LDEM_4.LBL");
    REQUIRE(path.has_value());
    const auto mesh = mesh::dem_to_mesh(io::read_dem(*path));
    const auto topo = mesh_topology(mesh);
    CHECK(topo.boundary_edges == 0);
    CHECK(topo.euler_characteristic == 2);
    const double r = 1737400;
    CHECK(total_area(mesh) == Approx(4 * std::numbers::pi * r * r).epsilon(0.01));
    CHECK(double(mesh.memory_bytes()) / double(mesh.vertex_count()) < 100);
}

TEST_CASE("dem_to_mesh: a projected tile's area is planimetric area x mean slope factor",
          "[mesh][real_data]") {
    const auto path = test::real_data("earth/bigtujunga_srtm30m_utm11.tif");
    REQUIRE(path.has_value());
    const Dem dem = io::read_dem(*path);
    const auto mesh = mesh::dem_to_mesh(dem);
    CHECK(mesh.frame == MeshFrame::map);
    // Slope factor sqrt(1 + gx^2 + gy^2) from central differences, over interior pixels.
    const double px = dem.transform[1], py = -dem.transform[5];
    double factor = 0;
    std::size_t n = 0;
    for (int r = 1; r + 1 < dem.height; ++r)
        for (int c = 1; c + 1 < dem.width; ++c) {
            const double gx = (dem.at(c + 1, r) - dem.at(c - 1, r)) / (2 * px);
            const double gy = (dem.at(c, r + 1) - dem.at(c, r - 1)) / (2 * py);
            factor += std::sqrt(1 + gx * gx + gy * gy);
            ++n;
        }
    factor /= double(n);
    const double planimetric = (dem.width - 1) * px * (dem.height - 1) * py;
    CHECK(total_area(mesh) == Approx(planimetric * factor).epsilon(0.01));
    CHECK(double(mesh.memory_bytes()) / double(mesh.vertex_count()) < 100);
}

TEST_CASE("dem_to_mesh: a radius grid's vertices are each pixel's radius along its lon and lat",
          "[mesh]") {
    // The rows of a lon/lat grid of radii take each column's cosine and sine of its longitude
    // once: each vertex must still be its own pixel's point, to the bit (a global grid in
    // degrees on a sphere of 255 km, whole and with NoData holes).
    Dem dem;
    dem.width = 360;
    dem.height = 180;
    dem.crs_wkt = R"(GEOGCRS["Sphere",DATUM["D",ELLIPSOID["S",255000,0]],CS[ellipsoidal,2],)"
                  R"(AXIS["lat",north,ANGLEUNIT["degree",0.0174532925199433]],)"
                  R"(AXIS["lon",east,ANGLEUNIT["degree",0.0174532925199433]]])";
    dem.transform = {-180.0, 1.0, 0, 90.0, 0, -1.0};
    dem.has_transform = true;
    geo::georeference(dem);
    dem.elevation = ElevationKind::radius;
    for (int r = 0; r < dem.height; ++r)
        for (int c = 0; c < dem.width; ++c)
            dem.values.push_back(255000 + 3000 * std::sin(c * 0.11) * std::cos(r * 0.07));
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1)
            for (std::size_t p = 0; p < dem.values.size(); p += 7) dem.values[p] = kNaN;
        const auto mesh = mesh::dem_to_mesh(dem);
        REQUIRE(mesh.frame == MeshFrame::body);
        const double degree = std::numbers::pi / 180;
        std::size_t checked = 0, differing = 0;
        for (int row = 0; row < dem.height; ++row) {
            if (row == mesh.pole_rows[0] || row == mesh.pole_rows[1]) continue;
            for (int col = 0; col < dem.width; ++col) {
                const std::size_t p = dem.index(col, row);
                const auto v = mesh.pixel_vertex[p];
                if (v < 0 || mesh.vertex_pixel[std::size_t(v)] != std::int32_t(p)) continue;
                const auto ll = dem.map_xy(col + 0.5, row + 0.5);
                const double value = dem.values[p], cl = std::cos(ll[1] * degree);
                const double xyz[3] = {value * cl * std::cos(ll[0] * degree),
                                       value * cl * std::sin(ll[0] * degree),
                                       value * std::sin(ll[1] * degree)};
                ++checked;
                for (int k = 0; k < 3; ++k)
                    differing += mesh.positions()[std::size_t(v)][std::size_t(k)] !=
                                 static_cast<float>(xyz[k] - mesh.origin[std::size_t(k)]);
            }
        }
        CHECK(checked > 50000);
        CHECK(differing == 0);
    }
}

TEST_CASE("dem_to_mesh: a lon/lat grid has the same shape in the body and map frames", "[mesh]") {
    // A Gaussian hill on a 0.001 degree grid at 45 N on WGS84.
    Dem dem;
    dem.width = dem.height = 40;
    dem.crs_wkt = "EPSG:4326";
    dem.transform = {7.0, 0.001, 0, 45.02, 0, -0.001};
    dem.has_transform = true;
    geo::georeference(dem);
    for (int r = 0; r < 40; ++r)
        for (int c = 0; c < 40; ++c) {
            const double x = (c - 19.5) * 78.8, y = (r - 19.5) * 111.1;
            dem.values.push_back(300 * std::exp(-(x * x + y * y) / (2 * 600.0 * 600.0)));
        }
    // The mesh code reads WKT; EPSG:4326 is accepted as any SetFromUserInput text.
    mesh::DemToMeshOptions body_frame, map_frame;
    body_frame.frame = MeshFrame::body;
    map_frame.frame = MeshFrame::map;
    const auto a = mesh::dem_to_mesh(dem, body_frame);
    const auto b = mesh::dem_to_mesh(dem, map_frame);
    REQUIRE(a.vertex_count() == b.vertex_count());
    // Same shape: every distance between grid neighbours (row, column and both diagonals)
    // agrees to within a centimetre. (Triangles may differ where the two diagonals of a
    // block tie to within float rounding.)
    double worst = 0;
    for (std::size_t v = 0; v + 41 < a.vertex_count(); ++v)
        for (std::size_t w : {v + 1, v + 40, v + 41}) {
            auto len = [&](const TriangleMesh& m) {
                const auto p = m.position(v), q = m.position(w);
                return std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
            };
            worst = std::max(worst, std::abs(len(a) - len(b)));
        }
    CHECK(worst < 0.01);
    // Degrees are never used as metres: a 0.001 degree step is about 79 m east-west here.
    const auto p0 = b.position(0), p1 = b.position(1);
    CHECK(std::hypot(p1[0] - p0[0], p1[1] - p0[1]) == Approx(78.8).epsilon(0.01));
    CHECK(total_area(a) == Approx(total_area(b)).epsilon(1e-5));
}

namespace {

// Whether two meshes hold the same position floats, byte for byte.
bool same_positions(const TriangleMesh& a, const TriangleMesh& b) {
    if (a.positions().size() != b.positions().size()) return false;
    return std::memcmp(a.positions().data(), b.positions().data(),
                       a.positions().size() * sizeof(a.positions()[0])) == 0;
}

// The positions freed and placed again from the DEM: the same floats, every vertex; and,
// when every value of the DEM is a float, from its values as floats (the run's packed
// heights) with the DEM's own values freed.
void check_positions_placed_again(const TriangleMesh& mesh, const Dem& dem) {
    TriangleMesh copy = mesh;
    REQUIRE(copy.release_positions());
    // Read while released: an error, not an empty array.
    CHECK_THROWS_WITH(copy.positions(), Catch::Contains("positions were read while released"));
    CHECK(copy.vertex_count() == mesh.vertex_count());
    mesh::restore_positions(dem, copy);
    CHECK_FALSE(copy.positions_released());
    CHECK(same_positions(copy, mesh));

    std::vector<float> heights(dem.values.begin(), dem.values.end());
    for (std::size_t i = 0; i < heights.size(); ++i)
        if (!std::isnan(dem.values[i]) && double(heights[i]) != dem.values[i]) return;
    TriangleMesh from_floats = mesh;
    REQUIRE(from_floats.release_positions());
    Dem without_values = dem;
    without_values.values.clear();
    heights.pop_back();
    CHECK_THROWS_WITH(mesh::restore_positions(without_values, heights, from_floats),
                      Catch::Contains("not one a pixel"));
    heights.push_back(static_cast<float>(dem.values.back()));
    mesh::restore_positions(without_values, heights, from_floats);
    CHECK(same_positions(from_floats, mesh));
}

// The same for `given` with its values rounded to floats (as a DEM whose values the run packs
// holds them), meshed with `options`.
void check_positions_placed_again(const Dem& given, const mesh::DemToMeshOptions& options = {}) {
    Dem dem = given;
    for (double& v : dem.values) v = static_cast<float>(v);
    check_positions_placed_again(mesh::dem_to_mesh(dem, options), dem);
}

// The grid's adjacency against the CSR finish_mesh makes from the same triangles: the same
// sorted lists, the same edge count. Returns the number of irregular vertices.
std::size_t check_grid_adjacency(const TriangleMesh& mesh, const Dem& dem) {
    REQUIRE(mesh.grid_adjacency());
    TriangleMesh csr = mesh;
    finish_mesh(csr);
    REQUIRE_FALSE(csr.grid_adjacency());
    std::size_t differ = 0, degrees = 0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const auto a = mesh.neighbors_of(v), b = csr.neighbors_of(v);
        degrees += a.size();
        differ += !std::equal(a.begin(), a.end(), b.begin(), b.end());
    }
    CHECK(differ == 0);
    CHECK(degrees == 2 * mesh.edge_count());
    CHECK(mesh.edge_count() == csr.edge_count());
    CHECK(mesh.vertex_areas == csr.vertex_areas);
    // The triangles made again from the grid once released: the same, in the same order,
    // from the diagonals recorded (no position is read: they are freed too).
    TriangleMesh released = mesh;
    REQUIRE(released.release_triangles());
    REQUIRE(released.release_positions());
    CHECK_THROWS_WITH(released.triangles(), Catch::Contains("triangles were read while released"));
    CHECK(released.triangle_count() == mesh.triangle_count());
    std::size_t count = 0, wrong = 0;
    detail::for_each_triangle(released, [&](std::size_t i, const std::array<std::int32_t, 3>& t) {
        wrong += i != count || i >= mesh.triangles().size() || mesh.triangles()[i] != t;
        ++count;
    });
    CHECK(count == mesh.triangle_count());
    CHECK(wrong == 0);
    // Its topology is counted the same without them.
    const auto before = mesh_topology(mesh), after = mesh_topology(released);
    CHECK(after.edges == before.edges);
    CHECK(after.boundary_edges == before.boundary_edges);
    CHECK(after.boundary_loops == before.boundary_loops);
    CHECK(after.components == before.components);
    CHECK(after.euler_characteristic == before.euler_characteristic);
    check_positions_placed_again(mesh, dem);
    // dem_to_mesh looks for pinches only next to missing pixels and the grid's edges: no
    // vertex it did not look at is pinched (the search over every vertex finds none left).
    TriangleMesh every = mesh;
    CHECK(split_pinched_vertices(every) == 0);
    return mesh.irregular_vertices.size();
}

}  // namespace

TEST_CASE("dem_to_mesh: the adjacency on the grid is the triangles' adjacency", "[mesh]") {
    SECTION("a full tile: no vertex needs its own list") {
        const Dem dem =
            grid_dem(40, 30, 10.0, [](int c, int r) { return 5.0 * std::sin(0.3 * c + 0.2 * r); });
        const auto mesh = mesh::dem_to_mesh(dem);
        CHECK(check_grid_adjacency(mesh, dem) == 0);
        // One range whose neighbours are read off the vertex numbers: rows 2 to 27.
        REQUIRE(mesh.uniform_ranges.size() == 1);
        CHECK(mesh.uniform_ranges[0] == std::array<std::int32_t, 2>{2 * 40, 28 * 40});
    }
    SECTION("NoData speckle: holes, pinches and isolated pixels") {
        std::uint32_t state = 12345;
        const Dem dem = grid_dem(60, 50, 10.0, [&](int c, int r) {
            state = state * 1664525u + 1013904223u;
            return (state >> 24) < 70 ? kNaN : double((c * 7 + r * 13) % 17);
        });
        const auto mesh = mesh::dem_to_mesh(dem);
        REQUIRE(mesh.pinched_vertices > 0);
        REQUIRE(mesh.isolated_vertices > 0);
        const auto irregular = check_grid_adjacency(mesh, dem);
        CHECK(irregular > 0);
        CHECK(irregular < mesh.vertex_count() / 2);
    }
    SECTION("a global grid: the seam and the poles") {
        const Dem dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
        const auto mesh = mesh::dem_to_mesh(dem);
        REQUIRE(mesh.seam_closed);
        REQUIRE(mesh.pole_vertices[0] >= 0);
        // The rows between the poles' (collapsed) rows are one range: rows 3 to 176 (the
        // north pole's row is one vertex, so a vertex is its pixel less 359).
        REQUIRE(mesh.uniform_ranges.size() == 1);
        CHECK(mesh.uniform_ranges[0] ==
              std::array<std::int32_t, 2>{3 * 360 - 359, 177 * 360 - 359});
        const auto irregular = check_grid_adjacency(mesh, dem);
        // The two seam columns, the poles and the rows next to them at most.
        CHECK(irregular >= 2);
        CHECK(irregular <= 2 * 180 + 2 + 2 * 360);
    }
    SECTION("a global grid with NoData across the seam") {
        Dem dem = io::read_dem(test::sample("moon_ldem1_global.tif"));
        for (int r = 40; r < 60; ++r)
            for (int c : {0, 1, 358, 359}) dem.values[dem.index(c, r)] = kNaN;
        dem.values[dem.index(0, 100)] = kNaN;
        const auto mesh = mesh::dem_to_mesh(dem);
        // Ranges above, between and below the holes, each with its own numbering.
        CHECK(mesh.uniform_ranges.size() == 3);
        check_grid_adjacency(mesh, dem);
    }
    SECTION("rows growing northwards: the triangles turn the other way") {
        Dem dem = grid_dem(30, 20, 10.0, [](int c, int r) { return std::cos(0.4 * c) * r; });
        dem.transform = {0, 10.0, 0, 0, 0, 10.0};
        geo::georeference(dem);
        const auto mesh = mesh::dem_to_mesh(dem);
        CHECK(mesh.triangles_flipped);
        check_grid_adjacency(mesh, dem);
    }
    SECTION("a mesh read from a file keeps its triangles") {
        TriangleMesh file =
            mesh::dem_to_mesh(grid_dem(5, 5, 1.0, [](int c, int r) { return double(c * r); }));
        file.pixel_vertex.clear();
        CHECK_FALSE(file.release_triangles());
        CHECK_FALSE(file.triangles().empty());
        CHECK_FALSE(file.release_positions());
        CHECK_FALSE(file.positions().empty());
    }
    SECTION("a grid two pixels wide keeps the CSR") {
        const Dem dem = grid_dem(2, 5, 1.0, [](int c, int r) { return double(c + r); });
        const auto mesh = mesh::dem_to_mesh(dem);
        CHECK_FALSE(mesh.grid_adjacency());
        CHECK(mesh.neighbor_offsets.size() == mesh.vertex_count() + 1);
    }
}

namespace {

// A crop, a global grid (seam, collapsed poles), a grid with NoData holes and pinches, and one
// with isolated pixels only (pixels alone in rings of NoData) and no pinch.
std::vector<Dem> grids_of_every_kind() {
    const auto ring = [](int c, int r) {
        const int dc = c % 20 - 10, dr = r % 15 - 7;
        return std::abs(dc) <= 1 && std::abs(dr) <= 1 && (dc != 0 || dr != 0);
    };
    const auto wave = [](int c, int r) { return std::sin(c * 0.3) * std::cos(r * 0.2) * 10; };
    std::vector<Dem> dems;
    dems.push_back(io::read_dem(test::sample("moon_ldem4_copernicus.tif")));
    dems.push_back(io::read_dem(test::sample("moon_ldem1_global.tif")));
    dems.push_back(grid_dem(97, 61, 1.0, [&](int c, int r) {
        const bool hole = (c * 7 + r * 13) % 11 == 0 || (c % 9 == 4 && r % 5 == 2);
        return ring(c, r) || hole ? kNaN : wave(c, r);
    }));
    // (isolated pixels without pinches: the areas summed by bands that hold their rows'
    // doubles only, the pixels without a vertex skipped)
    dems.push_back(
        grid_dem(83, 70, 1.0, [&](int c, int r) { return ring(c, r) ? kNaN : wave(c, r); }));
    return dems;
}

}  // namespace

TEST_CASE("dem_to_mesh: the same mesh whatever the thread count", "[mesh]") {
    // The numbering, the bounds, the rows of triangles, the areas and the directions run on
    // the threads.
    const std::vector<Dem> dems = grids_of_every_kind();
    for (const Dem& dem : dems) {
        TriangleMesh one, two;
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
            one = mesh::dem_to_mesh(dem);
        }
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
            two = mesh::dem_to_mesh(dem);
        }
        if (&dem == &dems[2]) {  // the holes make pinches and isolated pixels
            CHECK(two.pinched_vertices > 0);
            CHECK(two.isolated_vertices > 0);
        }
        if (&dem == &dems[3]) {
            CHECK(two.pinched_vertices == 0);
            CHECK(two.isolated_vertices > 0);
        }
        CHECK(one.pinched_vertices == two.pinched_vertices);
        CHECK(one.isolated_vertices == two.isolated_vertices);
        CHECK(one.vertex_pixel == two.vertex_pixel);
        CHECK(one.pixel_vertex == two.pixel_vertex);
        CHECK(one.pole_vertices == two.pole_vertices);
        CHECK(one.origin == two.origin);
        CHECK(one.positions() == two.positions());
        CHECK(one.triangles() == two.triangles());
        CHECK(one.vertex_areas == two.vertex_areas);
        // The areas (summed by bands of rows on the threads) are each vertex's thirds added in
        // triangle order, as one pass in order adds them.
        std::vector<double> sums(two.vertex_count(), 0.0);
        for (const auto& t : two.triangles()) {
            const auto &a = two.positions()[std::size_t(t[0])],
                       &b = two.positions()[std::size_t(t[1])],
                       &c = two.positions()[std::size_t(t[2])];
            const double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
            const double w[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
            const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                                 u[0] * w[1] - u[1] * w[0]};
            const double third = 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) / 3.0;
            for (const auto v : t) sums[std::size_t(v)] += third;
        }
        CHECK(std::vector<float>(sums.begin(), sums.end()) == two.vertex_areas);
        CHECK(one.neighbor_directions == two.neighbor_directions);
        CHECK(one.irregular_vertices == two.irregular_vertices);
        CHECK(one.irregular_neighbors == two.irregular_neighbors);
    }
}

TEST_CASE("dem_to_mesh: triangles released before the areas and the adjacency, the same mesh",
          "[mesh]") {
    // With release_triangles, the areas, the directions and the irregular vertices' lists walk
    // the triangles from the grid (in bands of rows on the threads): the same as from the
    // triangles held, at 1 and 2 threads, and the triangles made again are the same. A grid
    // with split pinches keeps its triangles. A crop, a global grid (seam and poles: irregular
    // vertices), a grid with holes and pinches, one with isolated pixels only.
    const std::vector<Dem> dems = grids_of_every_kind();
    mesh::DemToMeshOptions releasing;
    releasing.release_triangles = true;
    for (const Dem& dem : dems) {
        const auto held = mesh::dem_to_mesh(dem);
        for (const int threads : {1, 2}) {
            INFO(dem.width << " x " << dem.height << ", " << threads << " threads");
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
            auto released = mesh::dem_to_mesh(dem, releasing);
            CHECK(released.triangles_released() == (held.pinched_vertices == 0));
            CHECK(released.triangle_count() == held.triangle_count());
            CHECK(released.vertex_areas == held.vertex_areas);
            CHECK(released.neighbor_directions == held.neighbor_directions);
            CHECK(released.irregular_vertices == held.irregular_vertices);
            CHECK(released.irregular_offsets == held.irregular_offsets);
            CHECK(released.irregular_neighbors == held.irregular_neighbors);
            CHECK(released.grid_edges == held.grid_edges);
            CHECK(released.positions() == held.positions());
            CHECK(released.pixel_vertex == held.pixel_vertex);
            released.restore_triangles();
            CHECK_FALSE(released.triangles_released());
            CHECK(released.triangles() == held.triangles());
        }
    }
    CHECK(mesh::dem_to_mesh(dems[1], releasing).irregular_vertices.size() > 0);  // seam, poles
}

TEST_CASE("dem_to_mesh: frames and refusals", "[mesh]") {
    const Dem local = io::read_dem(test::sample("mars_hirise_crop.tif"));
    mesh::DemToMeshOptions body;
    body.frame = MeshFrame::body;
    CHECK_THROWS_AS(mesh::dem_to_mesh(local, body), Error);
    // A projected planetary grid in the map frame: flat, no seam even when global.
    const Dem moon = io::read_dem(test::sample("moon_ldem1_global.tif"));
    mesh::DemToMeshOptions map;
    map.frame = MeshFrame::map;
    const auto flat = mesh::dem_to_mesh(moon, map);
    CHECK_FALSE(flat.seam_closed);
    CHECK(mesh_topology(flat).euler_characteristic == 1);
    const Dem nothing = grid_dem(3, 3, 1.0, [](int c, int r) { return c == r ? 1.0 : kNaN; });
    CHECK_THROWS_AS(mesh::dem_to_mesh(nothing), Error);
}

TEST_CASE("dem_to_mesh: the same hill on a lon/lat grid and on a UTM grid has the same shape",
          "[mesh]") {
    // A Gaussian hill (300 m high, sigma 600 m) at 45 N 9 E, sampled on a 0.001 degree
    // lon/lat grid and on a 75 m UTM 32N grid. Both meshes must show the same hill: the same
    // height above their flat surroundings and the same extra area the relief adds.
    const double lon0 = 9.0, lat0 = 45.0, sigma = 600, top = 300;
    const GeographicLib::LocalCartesian local(lat0, lon0, 0);
    auto hill = [&](double east, double north) {
        return top * std::exp(-(east * east + north * north) / (2 * sigma * sigma));
    };
    Dem lonlat;
    lonlat.width = 50;
    lonlat.height = 36;
    lonlat.crs_wkt = "EPSG:4326";
    lonlat.transform = {lon0 - 0.025, 0.001, 0, lat0 + 0.018, 0, -0.001};
    lonlat.has_transform = true;
    geo::georeference(lonlat);
    for (int r = 0; r < lonlat.height; ++r)
        for (int c = 0; c < lonlat.width; ++c) {
            const auto p = lonlat.map_xy(c + 0.5, r + 0.5);
            double e, n, u;
            local.Forward(p[1], p[0], 0, e, n, u);
            lonlat.values.push_back(hill(e, n));
        }
    // The UTM grid centred on the same point (UTM 32N easting/northing of 9 E 45 N).
    int zone;
    bool northp;
    double x0, y0;
    GeographicLib::UTMUPS::Forward(lat0, lon0, zone, northp, x0, y0, 32);
    Dem utm;
    utm.width = utm.height = 52;
    utm.crs_wkt = "EPSG:32632";
    utm.transform = {x0 - 26 * 75.0, 75, 0, y0 + 26 * 75.0, 0, -75};
    utm.has_transform = true;
    geo::georeference(utm);
    for (int r = 0; r < utm.height; ++r)
        for (int c = 0; c < utm.width; ++c) {
            const auto p = utm.map_xy(c + 0.5, r + 0.5);
            double lat, lon;
            GeographicLib::UTMUPS::Reverse(32, true, p[0], p[1], lat, lon);
            double e, n, u;
            local.Forward(lat, lon, 0, e, n, u);
            utm.values.push_back(hill(e, n));
        }
    auto relief = [](const TriangleMesh& m) {
        // Extra area over the flat footprint, and the top's height above the lowest vertex.
        double area = 0, flat = 0, lo = 1e300, hi = -1e300;
        for (const auto& t : m.triangles()) {
            const auto a = m.position(t[0]), b = m.position(t[1]), c = m.position(t[2]);
            const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            const double nx = u[1] * v[2] - u[2] * v[1], ny = u[2] * v[0] - u[0] * v[2],
                         nz = u[0] * v[1] - u[1] * v[0];
            area += 0.5 * std::sqrt(nx * nx + ny * ny + nz * nz);
            flat += 0.5 * std::abs(nz);
        }
        for (std::size_t v = 0; v < m.vertex_count(); ++v)
            lo = std::min(lo, m.position(v)[2]), hi = std::max(hi, m.position(v)[2]);
        return std::pair{area - flat, hi - lo};
    };
    mesh::DemToMeshOptions tangent_plane;
    tangent_plane.frame = MeshFrame::map;
    const auto a = relief(mesh::dem_to_mesh(lonlat, tangent_plane));
    const auto b = relief(mesh::dem_to_mesh(utm));  // map frame: UTM metres
    CHECK(a.second == Approx(b.second).epsilon(0.005));
    CHECK(a.first == Approx(b.first).epsilon(0.005));
    CHECK(a.first > 0.02 * 2 * std::numbers::pi * sigma * sigma);  // the hill adds real area
    // Every way of placing a vertex places it again the same (the positions freed during the
    // Reeb graph and the simplification): a tangent plane, map metres, and the body frame from
    // lon/lat and through the CRS's transformation.
    mesh::DemToMeshOptions body;
    body.frame = MeshFrame::body;
    SECTION("lon/lat, tangent plane") {
        check_positions_placed_again(lonlat, tangent_plane);
    }
    SECTION("lon/lat, body") {
        check_positions_placed_again(lonlat, body);
    }
    SECTION("UTM, map metres") {
        check_positions_placed_again(utm);
    }
    SECTION("UTM, body") {
        check_positions_placed_again(utm, body);
    }
    SECTION("another grid is refused") {
        TriangleMesh m = mesh::dem_to_mesh(utm);
        REQUIRE(m.release_positions());
        CHECK_THROWS_AS(mesh::restore_positions(lonlat, m), Error);
    }
}

TEST_CASE("dem_to_mesh reports every pass of a large grid, never going back", "[mesh]") {
    // 700 x 700 pixels: about a million triangles, so that every pass reports several times
    // (every 2^18 items) and the slices of the large blocks report too; pinched pixels and
    // NoData holes give the splitting and the removal passes work.
    const Dem dem = grid_dem(700, 700, 10.0, [](int c, int r) {
        if ((c / 50 + r / 50) % 7 == 3 && c % 50 < 20 && r % 50 < 20) return kNaN;
        if (c % 97 == 5 && r % 89 == 7) return kNaN;
        return 30 * std::sin(c * 0.05) * std::cos(r * 0.037) + 0.1 * ((c * 31 + r * 17) % 13);
    });
    std::vector<double> seen;
    const auto mesh = mesh::dem_to_mesh(dem, {}, [&](double f, std::string_view message) {
        CHECK(message == "mesh");
        seen.push_back(f);
        return true;
    });
    CHECK(mesh.triangle_count() > 900000);
    CHECK(std::is_sorted(seen.begin(), seen.end()));
    CHECK(seen.size() > 100);
    CHECK(seen.back() == 1.0);
    // No slice of the bar larger than a tenth is silent.
    double widest = 0;
    for (std::size_t i = 1; i < seen.size(); ++i) widest = std::max(widest, seen[i] - seen[i - 1]);
    CHECK(widest < 0.1);
}
