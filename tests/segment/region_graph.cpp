#include <catch2/catch.hpp>

#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "support/segment_support.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/geo/body.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/segment/regions.hpp"

using namespace terrain;
using segment::Landform;

namespace {

// A flat local grid (no CRS) of w x h pixels of `pixel` metres.
Dem flat_grid(int w, int h, double pixel) {
    Dem dem;
    dem.width = w;
    dem.height = h;
    dem.transform = {100, pixel, 0, 200, 0, -pixel};
    dem.has_transform = true;
    dem.body = geo::body_from_crs("");
    dem.values.assign(static_cast<std::size_t>(w) * h, 10.0);
    return dem;
}

// Graph invariants every segmentation must satisfy.
void check_graph(const test::SegmentedTile& t) {
    const auto& g = t.graph;
    REQUIRE(g.regions.size() == t.region_count);
    std::size_t vertices = 0;
    for (std::size_t i = 0; i < g.regions.size(); ++i) {
        const auto& r = g.regions[i];
        CHECK(r.id == i + 1);
        vertices += r.vertex_count;
        CHECK(r.field_min <= r.field_mean);
        CHECK(r.field_mean <= r.field_max);
        CHECK(r.landform == segment::landform_of(r.field_mean));
        REQUIRE(r.representative_vertex >= 0);
        CHECK(t.labels[std::size_t(r.representative_vertex)] == r.id);
    }
    CHECK(vertices == t.mesh.vertex_count());
    // Edges: sorted, a < b, exactly the label pairs joined by a mesh edge, with their counts.
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> cut;
    for (std::size_t v = 0; v < t.mesh.vertex_count(); ++v)
        for (const auto nb : t.mesh.neighbors_of(v)) {
            const auto w = std::size_t(nb);
            const auto a = t.labels[v], b = t.labels[w];
            if (w > v && a != b) ++cut[{std::min(a, b), std::max(a, b)}];
        }
    REQUIRE(g.edges.size() == cut.size());
    std::vector<std::size_t> degree(g.regions.size(), 0);
    auto it = cut.begin();
    for (const auto& e : g.edges) {
        CHECK(e.a < e.b);
        CHECK(std::make_pair(e.a, e.b) == it->first);
        CHECK(e.mesh_edges == it->second);
        CHECK(e.boundary_length_m > 0);
        CHECK(e.contrast ==
              Approx(std::abs(g.regions[e.a - 1].field_mean - g.regions[e.b - 1].field_mean)));
        ++degree[e.a - 1];
        ++degree[e.b - 1];
        ++it;
    }
    for (std::size_t i = 0; i < g.regions.size(); ++i)
        CHECK(g.regions[i].neighbor_count == degree[i]);
}

// f(graph, mesh) for region_graph on t's labels at one and two threads, t's mesh with its
// triangles held and released.
template <class F>
void for_each_region_graph(const test::SegmentedTile& t, F&& f) {
    TriangleMesh released = t.mesh;
    REQUIRE(released.release_triangles());
    for (const TriangleMesh* m : {&t.mesh, static_cast<const TriangleMesh*>(&released)})
        for (const int threads : {1, 2}) {
            CAPTURE(threads, m == &released);
            segment::RegionGraph g;
            tbb::task_arena(threads).execute(
                [&] { g = segment::region_graph(*m, t.field, t.labels, t.region_count, &t.dem); });
            f(g, *m);
        }
}

}  // namespace

TEST_CASE("landform classes follow Koenderink's intervals on [0,100]", "[regions]") {
    CHECK(segment::landform_of(0) == Landform::cup);
    CHECK(segment::landform_of(6.2499) == Landform::cup);
    CHECK(segment::landform_of(6.25) == Landform::trough);
    CHECK(segment::landform_of(18.75) == Landform::rut);
    CHECK(segment::landform_of(31.25) == Landform::saddle_rut);
    CHECK(segment::landform_of(43.75) == Landform::saddle);
    CHECK(segment::landform_of(50) == Landform::saddle);
    CHECK(segment::landform_of(56.25) == Landform::saddle_ridge);
    CHECK(segment::landform_of(68.75) == Landform::ridge);
    CHECK(segment::landform_of(81.25) == Landform::dome);
    CHECK(segment::landform_of(93.75) == Landform::cap);
    CHECK(segment::landform_of(100) == Landform::cap);
    CHECK(segment::landform_of(-3) == Landform::cup);
    CHECK(segment::landform_of(130) == Landform::cap);
    CHECK(std::string(segment::to_string(Landform::saddle_rut)) == "saddle rut");
    CHECK(std::string(segment::to_string(Landform::cap)) == "cap");
}

TEST_CASE("region_graph on a flat grid: known areas, boundary lengths and centres", "[regions]") {
    const int W = 20, H = 12;
    const double pixel = 2.0;
    SECTION("left and right halves") {
        const auto t = test::segment_tile(flat_grid(W, H, pixel),
                                          [](int col, int) { return col < 8 ? 1u : 2u; });
        check_graph(t);
        const auto& g = t.graph;
        CHECK(g.point_frame == segment::PointFrame::map);
        CHECK(g.point_crs_wkt.empty());
        CHECK(g.regions[0].pixel_count == 8 * H);
        CHECK(g.regions[1].pixel_count == 12 * H);
        CHECK(g.regions[0].area_m2 == Approx(8 * H * pixel * pixel));
        CHECK(g.regions[1].area_m2 == Approx(12 * H * pixel * pixel));
        // The cut runs through the midpoints of the cut edges, from the first row's centre
        // to the last one's: (H - 1) pixels long.
        REQUIRE(g.edges.size() == 1);
        CHECK(g.edges[0].boundary_length_m == Approx((H - 1) * pixel));
        // H horizontal edges and one diagonal per row of blocks.
        CHECK(g.edges[0].mesh_edges == std::size_t(H + H - 1));
        // The representative vertex is as far as can be from the cut and the tile's edge.
        const auto& right = g.regions[1];
        const int col = t.mesh.vertex_pixel[std::size_t(right.representative_vertex)] % W;
        const int row = t.mesh.vertex_pixel[std::size_t(right.representative_vertex)] / W;
        CHECK(col >= 12);
        CHECK(col <= 15);
        CHECK(row >= 4);
        CHECK(row <= 7);
        CHECK(right.point[0] == Approx(100 + (col + 0.5) * pixel));
        CHECK(right.point[1] == Approx(200 - (row + 0.5) * pixel));
        CHECK(right.point[2] == Approx(10));
        // A flat surface has the planar shape index 50: a saddle-class region.
        CHECK(right.field_mean == Approx(50).margin(1e-3));
        CHECK(right.landform == Landform::saddle);
        CHECK(g.edges[0].contrast == Approx(0).margin(1e-3));
    }
    SECTION("top and bottom halves") {
        const auto t = test::segment_tile(flat_grid(W, H, pixel),
                                          [](int, int row) { return row < 5 ? 1u : 2u; });
        check_graph(t);
        REQUIRE(t.graph.edges.size() == 1);
        CHECK(t.graph.edges[0].boundary_length_m == Approx((W - 1) * pixel));
    }
    SECTION("quadrants") {
        const auto t = test::segment_tile(flat_grid(W, H, pixel), [](int col, int row) {
            return 1u + (col >= 10 ? 1u : 0u) + (row >= 6 ? 2u : 0u);
        });
        check_graph(t);
        // Each quadrant touches its two side neighbours; the middle block's diagonal joins
        // one diagonal pair too.
        CHECK(t.graph.edges.size() == 5);
        double total = 0;
        for (const auto& e : t.graph.edges) total += e.boundary_length_m;
        // Two straight cuts (19 + 11 pixels) give the total, whatever the junction does.
        CHECK(total == Approx((W - 1 + H - 1) * pixel).epsilon(0.02));
    }
}

TEST_CASE("region_graph areas on the Moon are the pixels' footprints on the sphere", "[regions]") {
    const Dem moon =
        test::crop(io::read_dem(test::sample("moon_ldem4_copernicus.tif")), 40, 20, 36, 30);
    const auto t = test::segment_tile(moon, test::voronoi_cells(moon, 3, 2));
    check_graph(t);
    const auto& g = t.graph;
    CHECK(g.point_frame == segment::PointFrame::lonlat);
    CHECK_FALSE(g.point_crs_wkt.empty());
    double sum = 0;
    std::size_t pixels = 0;
    for (const auto& r : g.regions) {
        // The library's exact parallel-bounded areas and the geodesic quadrilaterals of the
        // corners differ by about 1e-6 for 7.6 km pixels on the Moon (edges 4e-3 radians).
        CHECK(r.area_m2 == Approx(test::labelled_area(t.dem, t.pixels, r.id)).epsilon(5e-6));
        sum += r.area_m2;
        pixels += r.pixel_count;
        // The representative point is in the tile (Copernicus, about 20 W 10 N).
        CHECK(r.point[0] > -40);
        CHECK(r.point[0] < 0);
        CHECK(r.point[1] > -5);
        CHECK(r.point[1] < 25);
    }
    CHECK(pixels == 36u * 30u);
    CHECK(sum == Approx(test::labelled_area(t.dem, t.pixels)).epsilon(5e-6));
}

TEST_CASE("region_graph areas on a UTM tile match geodesic pixel areas", "[regions][real_data]") {
    const auto path = test::real_data("earth/bigtujunga_srtm30m_utm11.tif");
    REQUIRE(path.has_value());  // tests/data is in the repository
    const Dem srtm = test::crop(io::read_dem(*path), 300, 200, 40, 20);
    // One region per pixel: each area is one pixel's, interpolated between exact nodes.
    // (PolygonArea itself is good to about 1e-6 m^2 on a 30 m pixel far from the equator.)
    const auto t = test::segment_tile(
        srtm, [](int col, int row) { return std::uint32_t(row * 40 + col + 1); });
    REQUIRE(t.region_count == 800);
    for (int row = 0; row < 20; row += 3)
        for (int col = 0; col < 40; col += 3) {
            const auto& r = t.graph.regions[std::size_t(row * 40 + col)];
            CHECK(r.pixel_count == 1);
            CHECK(r.area_m2 == Approx(test::pixel_area(srtm, col, row)).epsilon(1e-8));
        }
    // UTM 11N squares of 30 m near 34 N, 118 W are smaller on the ellipsoid (k < 1 there).
    CHECK(t.graph.regions[0].area_m2 > 899);
    CHECK(t.graph.regions[0].area_m2 < 901);
    // Earth's points are WGS 84 lon/lat.
    CHECK(t.graph.regions[0].point[0] == Approx(-118.2).margin(0.3));
    CHECK(t.graph.regions[0].point[1] == Approx(34.3).margin(0.3));
}

TEST_CASE("region_graph of a mesh without DEM uses the mesh's areas and positions", "[regions]") {
    const Dem mars = io::read_dem(test::sample("mars_hirise_crop.tif"));
    const auto mesh = mesh::dem_to_mesh(mars);
    const int W = mars.width;
    std::vector<float> field(mesh.vertex_count());
    std::vector<std::uint32_t> labels(mesh.vertex_count());
    for (std::size_t v = 0; v < labels.size(); ++v) {
        labels[v] = mesh.vertex_pixel[v] / W < 60 ? 1 : 2;
        field[v] = labels[v] == 1 ? 10.0f : 90.0f;
    }
    const auto g = segment::region_graph(mesh, field, labels, 2, nullptr);
    CHECK(g.point_frame == segment::PointFrame::mesh);
    CHECK(g.regions[0].pixel_count == 0);
    CHECK(g.regions[0].area_m2 == g.regions[0].surface_area_m2);
    CHECK(g.regions[0].landform == Landform::trough);
    CHECK(g.regions[1].landform == Landform::dome);
    REQUIRE(g.edges.size() == 1);
    CHECK(g.edges[0].contrast == Approx(80));
    // The cut between rows 59 and 60 runs in 3-D through the midpoints of the vertical edges
    // and of the diagonals between them: at least the polyline through the former.
    const auto vertex = mesh::pixel_to_vertex(mesh, mars);
    auto middle = [&](int col) {
        const auto a = mesh.position(std::size_t(vertex[mars.index(col, 59)]));
        const auto b = mesh.position(std::size_t(vertex[mars.index(col, 60)]));
        return std::array<double, 3>{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
    };
    double polyline = 0;
    for (int c = 0; c + 1 < W; ++c) {
        const auto p = middle(c), q = middle(c + 1);
        polyline += std::hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]);
    }
    CHECK(polyline > (W - 1) * 1.01);
    CHECK(g.edges[0].boundary_length_m >= polyline * (1 - 1e-9));
    CHECK(g.edges[0].boundary_length_m < polyline * 1.05);
    const auto p = mesh.position(std::size_t(g.regions[1].representative_vertex));
    CHECK(g.regions[1].point == p);
}

TEST_CASE("region_graph refuses labels that do not number the regions", "[regions][bad_input]") {
    const Dem dem = flat_grid(6, 5, 1);
    const auto mesh = mesh::dem_to_mesh(dem);
    const std::vector<float> field(mesh.vertex_count(), 50.f);
    std::vector<std::uint32_t> labels(mesh.vertex_count(), 1);
    CHECK_NOTHROW(segment::region_graph(mesh, field, labels, 1, &dem));
    CHECK_THROWS_AS(segment::region_graph(mesh, field, labels, 2, &dem), Error);  // 2 unused
    labels[3] = 0;
    CHECK_THROWS_AS(segment::region_graph(mesh, field, labels, 1, &dem), Error);
    labels[3] = 5;
    CHECK_THROWS_AS(segment::region_graph(mesh, field, labels, 1, &dem), Error);
    labels.pop_back();
    CHECK_THROWS_AS(segment::region_graph(mesh, field, labels, 1, &dem), Error);
}

TEST_CASE("label_pixels: NoData pixels are 0, every valid pixel has its vertex's label",
          "[regions]") {
    Dem vesta = test::crop(io::read_dem(test::sample("vesta_hamo_tile.lbl")), 100, 100, 30, 24);
    for (int r = 8; r < 14; ++r)
        for (int c = 10; c < 17; ++c) vesta.values[vesta.index(c, r)] = std::nan("");
    const auto t = test::segment_tile(vesta, test::voronoi_cells(vesta, 3, 3));
    check_graph(t);
    const auto vertex = mesh::pixel_to_vertex(t.mesh, t.dem);
    for (std::size_t p = 0; p < t.pixels.size(); ++p) {
        CHECK((t.pixels[p] == 0) == (vertex[p] < 0));
        if (vertex[p] >= 0) CHECK(t.pixels[p] == t.labels[std::size_t(vertex[p])]);
    }
    std::size_t counted = 0;
    for (const auto& r : t.graph.regions) counted += r.pixel_count;
    CHECK(counted == 30u * 24u - 6u * 7u);
}

TEST_CASE("Representative vertices are the deepest of one BFS, whatever the threads", "[regions]") {
    // The distances from the regions' edges go level by level in parallel, and a grid's
    // boundary is counted in bands of rows: each region's vertex must be the one a plain BFS
    // gives (the largest distance through the region from its cut edges and the mesh's
    // boundary, ties to the lowest index), at one and two threads, triangles held or released.
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    const auto t = test::segment_tile(dem, test::voronoi_cells(dem, 7, 5));
    const auto& mesh = t.mesh;
    const std::size_t n = mesh.vertex_count();
    // The reference: triangle counts per vertex, then one BFS queue.
    std::vector<int> triangles(n, 0);
    for (const auto& tri : mesh.triangles())
        for (const auto v : tri) ++triangles[std::size_t(v)];
    std::vector<int> depth(n, -1);
    std::vector<std::size_t> queue;
    for (std::size_t v = 0; v < n; ++v) {
        bool source = std::size_t(triangles[v]) != mesh.degree(v);
        for (const auto w : mesh.neighbors_of(v)) source |= t.labels[std::size_t(w)] != t.labels[v];
        if (source) {
            depth[v] = 0;
            queue.push_back(v);
        }
    }
    for (std::size_t head = 0; head < queue.size(); ++head)
        for (const auto nb : mesh.neighbors_of(queue[head])) {
            const auto w = std::size_t(nb);
            if (depth[w] >= 0 || t.labels[w] != t.labels[queue[head]]) continue;
            depth[w] = depth[queue[head]] + 1;
            queue.push_back(w);
        }
    std::vector<std::int32_t> expected(t.region_count, -1);
    for (std::size_t v = 0; v < n; ++v) {
        auto& b = expected[t.labels[v] - 1];
        if (b < 0 || depth[v] > depth[std::size_t(b)]) b = std::int32_t(v);
    }
    REQUIRE(t.region_count == 35);
    REQUIRE(*std::max_element(depth.begin(), depth.end()) > 10);
    for_each_region_graph(t, [&](const segment::RegionGraph& g, const TriangleMesh&) {
        for (std::uint32_t r = 0; r < t.region_count; ++r)
            CHECK(g.regions[r].representative_vertex == expected[r]);
    });
}

TEST_CASE("Boundary lengths are one pass's sums in triangle order, whatever the threads",
          "[regions]") {
    // The cut edges are counted on every thread and a released grid's crossing triangles are
    // found by rows on every thread: each pair's count and length (a sum of doubles in
    // triangle order) must be those of one pass over the triangles in order, to the bit, at
    // one and two threads, triangles held or released.
    const auto dem = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    const auto t = test::segment_tile(dem, test::voronoi_cells(dem, 7, 5));
    const auto& mesh = t.mesh;
    using Point = std::array<double, 3>;
    const auto mid = [](const Point& p, const Point& q) {
        return Point{(p[0] + q[0]) / 2, (p[1] + q[1]) / 2, (p[2] + q[2]) / 2};
    };
    const auto dist = [](const Point& p, const Point& q) {
        return std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
    };
    const auto key = [](std::uint32_t a, std::uint32_t b) {
        return std::make_pair(std::min(a, b), std::max(a, b));
    };
    std::map<std::pair<std::uint32_t, std::uint32_t>, double> length;
    for (const auto& tri : mesh.triangles()) {
        const std::uint32_t l[3] = {t.labels[std::size_t(tri[0])], t.labels[std::size_t(tri[1])],
                                    t.labels[std::size_t(tri[2])]};
        if (l[0] == l[1] && l[1] == l[2]) continue;
        const Point p[3] = {mesh.position(std::size_t(tri[0])), mesh.position(std::size_t(tri[1])),
                            mesh.position(std::size_t(tri[2]))};
        const Point m[3] = {mid(p[0], p[1]), mid(p[1], p[2]), mid(p[2], p[0])};
        if (l[0] != l[1] && l[1] != l[2] && l[2] != l[0]) {
            const Point c = {(p[0][0] + p[1][0] + p[2][0]) / 3, (p[0][1] + p[1][1] + p[2][1]) / 3,
                             (p[0][2] + p[1][2] + p[2][2]) / 3};
            for (int k = 0; k < 3; ++k) length[key(l[k], l[(k + 1) % 3])] += dist(c, m[k]);
            continue;
        }
        const int k = l[0] == l[1] ? 2 : (l[1] == l[2] ? 0 : 1);
        length[key(l[k], l[(k + 1) % 3])] += dist(m[(k + 2) % 3], m[k]);
    }
    REQUIRE(length.size() > 50);
    for_each_region_graph(t, [&](const segment::RegionGraph& g, const TriangleMesh& m) {
        REQUIRE(g.edges.size() == length.size());
        std::size_t differing = 0;
        for (const auto& e : g.edges) differing += e.boundary_length_m != length[{e.a, e.b}];
        CHECK(differing == 0);
        check_graph({t.dem, m, t.field, t.labels, t.region_count, g, {}});
    });
}
