// The shape index's rings window fits its vertices four at a time in the lanes of vectors
// (fit_curvatures_batch) and reads two rings of neighbours off the grid's directions
// (gather_two_rings_on_grid): both must give each vertex the bits of the one-vertex path.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "../../libterrain/src/field/shape_index_fit.hpp"
#include "support/test_support.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/geo/georeference.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;
using field::detail::FitBatch;
using field::detail::kFitLanes;
using field::detail::Vec3;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// A local-grid DEM (no CRS) of w x h pixels of 30 m, z(col, row) (NaN: NoData).
template <class F>
Dem grid_dem(int w, int h, F z) {
    Dem dem;
    dem.width = w;
    dem.height = h;
    dem.transform = {0, 30.0, 0, 0, 0, -30.0};
    dem.has_transform = true;
    geo::georeference(dem);
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) dem.values.push_back(z(c, r));
    return dem;
}

std::vector<TriangleMesh> test_meshes() {
    std::vector<TriangleMesh> meshes;
    meshes.push_back(mesh::dem_to_mesh(io::read_dem(test::sample("moon_ldem4_copernicus.tif"))));
    meshes.push_back(mesh::dem_to_mesh(io::read_dem(test::sample("moon_ldem1_global.tif"))));
    // Holes, pinches and isolated pixels among noisy hills.
    meshes.push_back(mesh::dem_to_mesh(grid_dem(97, 61, [](int c, int r) {
        const int dc = c % 20 - 10, dr = r % 15 - 7;
        const bool ring = std::abs(dc) <= 1 && std::abs(dr) <= 1 && (dc != 0 || dr != 0);
        return ring || (c * 7 + r * 13) % 11 == 0
                   ? kNaN
                   : std::sin(c * 0.3) * std::cos(r * 0.2) * 800 + ((c * 31 + r * 17) % 7) * 40.0;
    })));
    return meshes;
}

// A unit normal for vertex v: its position's direction, tilted by the vertex number (any unit
// vector will do: the two paths must agree on it).
Vec3 some_normal(const TriangleMesh& mesh, std::int32_t v) {
    const auto& p = mesh.positions()[std::size_t(v)];
    const double t = 0.1 * std::sin(double(v));
    Vec3 n{p[0] + mesh.origin[0] + t * 1e5, p[1] + mesh.origin[1], p[2] + mesh.origin[2] + 1e3};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return {n[0] / len, n[1] / len, n[2] / len};
}

bool same_bits(double a, double b) {
    return std::memcmp(&a, &b, sizeof(double)) == 0;
}

}  // namespace

TEST_CASE("shape index: the vertices fitted four at a time get the one-vertex fit's bits",
          "[shape_index]") {
    std::size_t lanes = 0, fitted = 0, differing = 0;
    for (const auto& mesh : test_meshes()) {
        const auto n = static_cast<std::int32_t>(mesh.vertex_count());
        field::detail::Scratch s;
        std::array<std::vector<std::int32_t>, kFitLanes> lists;
        for (std::int32_t v0 = 0; v0 + kFitLanes <= n; v0 += kFitLanes) {
            FitBatch batch;
            for (int l = 0; l < kFitLanes; ++l) {
                const std::int32_t v = v0 + l;
                field::detail::gather_where(
                    mesh, v, 2, [](std::int32_t) { return true; }, s);
                auto& list = lists[std::size_t(l)];
                list.assign(s.gathered.begin() + 1, s.gathered.end());
                // Every 7th group: lanes the vectors cannot finish (all neighbours one vertex,
                // a singular system; the vertex itself, a zero scale; three neighbours).
                if (v0 % (7 * kFitLanes) == 0 && !list.empty()) {
                    if (l == 1) list.assign(list.size(), list[0]);
                    if (l == 2) list.assign(list.size(), v);
                    if (l == 3) list.resize(std::min<std::size_t>(list.size(), 3));
                }
                batch.vertex[std::size_t(l)] = v;
                batch.neighbours[std::size_t(l)] = list.data();
                batch.normal[std::size_t(l)] = some_normal(mesh, v);
                batch.m[std::size_t(l)] = list.size();
            }
            std::array<field::PrincipalCurvatures, kFitLanes> k;
            std::array<double, kFitLanes> scale{};
            std::array<bool, kFitLanes> ok{};
            field::detail::fit_curvatures_batch(mesh, batch, k, scale, ok);
            for (std::size_t l = 0; l < std::size_t(kFitLanes); ++l) {
                field::PrincipalCurvatures one;
                double one_scale = 0;
                const bool one_ok =
                    field::detail::fit_curvatures(mesh, batch.vertex[l], batch.normal[l],
                                                  batch.neighbours[l], batch.m[l], one, one_scale);
                ++lanes;
                fitted += one_ok;
                if (ok[l] != one_ok ||
                    (one_ok && (!same_bits(k[l].k1, one.k1) || !same_bits(k[l].k2, one.k2) ||
                                !same_bits(scale[l], one_scale))))
                    ++differing;
            }
        }
    }
    CHECK(lanes > 20000);
    CHECK(fitted > lanes * 9 / 10);
    CHECK(fitted < lanes);  // (the lanes made to fail)
    CHECK(differing == 0);
}

TEST_CASE("shape index: two rings read off the grid are the rings gathered on the mesh",
          "[shape_index]") {
    std::size_t read = 0, vertices = 0, differing = 0;
    for (const auto& mesh : test_meshes()) {
        REQUIRE(mesh.grid_adjacency());
        field::detail::Scratch s;
        std::vector<std::int32_t> on_grid;
        for (std::int32_t v = 0; v < std::int32_t(mesh.vertex_count()); ++v) {
            ++vertices;
            if (!field::detail::gather_two_rings_on_grid(mesh, v, on_grid)) continue;
            ++read;
            field::detail::gather_where(
                mesh, v, 2, [](std::int32_t) { return true; }, s);
            differing += on_grid != s.gathered;
        }
    }
    CHECK(read > vertices * 8 / 10);  // most vertices take the grid's way
    CHECK(read < vertices);           // and some (seam, poles, holes) do not
    CHECK(differing == 0);
}

TEST_CASE("shape index: the rings window's curvatures are the one-vertex path's", "[shape_index]") {
    // principal_curvatures (batches, two rings off the grid) against each vertex gathered and
    // fitted alone (mesh_fit), with the same vertex normals.
    std::size_t vertices = 0, differing = 0;
    for (const auto& mesh : test_meshes()) {
        const field::ShapeIndexOptions options;
        const auto curvatures = field::principal_curvatures(mesh, options);
        const auto normals = field::detail::vertex_normals(mesh);
        REQUIRE(curvatures.size() == mesh.vertex_count());
        field::detail::Scratch s;
        for (std::int32_t v = 0; v < std::int32_t(mesh.vertex_count()); ++v) {
            field::PrincipalCurvatures k;
            double scale = 0;
            field::PrincipalCurvatures want;  // (principal_curvatures leaves a failed fit at 0)
            if (field::detail::mesh_fit(mesh, v, normals[std::size_t(v)], options, nullptr, s, k,
                                        scale))
                want = {k.k1 / scale, k.k2 / scale};
            ++vertices;
            differing += !same_bits(curvatures[std::size_t(v)].k1, want.k1) ||
                         !same_bits(curvatures[std::size_t(v)].k2, want.k2);
        }
    }
    CHECK(vertices > 50000);
    CHECK(differing == 0);
}

TEST_CASE("shape index: rings gathered with a small set of the vertices seen are gather_where's",
          "[shape_index]") {
    // The batches gather the vertices the grid does not give in order with a small set instead
    // of a stamp per vertex: the same vertices in the same order, at 1 to 3 rings, poles (360
    // neighbours on the global Moon) included.
    std::size_t vertices = 0, differing = 0, largest = 0;
    for (const auto& mesh : test_meshes()) {
        field::detail::Scratch s;
        field::detail::SmallVertexSet visited;
        std::vector<std::int32_t> gathered;
        for (int rings = 1; rings <= 3; ++rings)
            for (std::int32_t v = 0; v < std::int32_t(mesh.vertex_count()); v += rings) {
                field::detail::gather_where(
                    mesh, v, rings, [](std::int32_t) { return true; }, s);
                field::detail::gather_rings(mesh, v, rings, visited, gathered);
                ++vertices;
                differing += gathered != s.gathered;
                largest = std::max(largest, gathered.size());
            }
    }
    CHECK(vertices > 100000);
    CHECK(largest > 700);  // a pole's two rings
    CHECK(differing == 0);
}

TEST_CASE("shape index: the normals made a band of pixel rows at a time are the whole mesh's",
          "[shape_index]") {
    // band_normals against vertex_normals of the mesh with its triangles held, bit for bit, on
    // bands of 1, 5 and 64 rows: poles and the seam (the global Moon), NoData, the grid's edges.
    std::size_t meshes = 0, compared = 0, differing = 0;
    auto dems = test_meshes();
    dems.push_back(mesh::dem_to_mesh(grid_dem(83, 70, [](int c, int r) {
        return (c / 9 + r / 7) % 5 == 0 && c % 9 > 2 && r % 7 > 2
                   ? kNaN
                   : std::cos(c * 0.21) * std::sin(r * 0.17) * 600 + ((c * 13 + r * 7) % 5) * 30.0;
    })));
    for (auto& mesh : dems) {
        const auto whole = field::detail::vertex_normals(mesh);
        if (!mesh.release_triangles() || !field::detail::normals_by_bands(mesh)) continue;
        ++meshes;
        const int W = mesh.grid_width, H = mesh.grid_height;
        field::detail::Normals band;
        for (const int rows : {1, 5, 64})
            for (int r0 = 0; r0 < H; r0 += rows) {
                const int r1 = std::min(H, r0 + rows);
                field::detail::band_normals(mesh, r0, r1, band);
                for (std::size_t p = std::size_t(r0) * W; p < std::size_t(r1) * W; ++p) {
                    const auto v = mesh.pixel_vertex[p];
                    if (v < 0) continue;
                    ++compared;
                    for (int k = 0; k < 3; ++k)
                        differing += !same_bits(band[std::size_t(v)][k], whole[std::size_t(v)][k]);
                }
            }
    }
    CHECK(meshes >= 3);
    CHECK(compared > 100000);
    CHECK(differing == 0);
}
