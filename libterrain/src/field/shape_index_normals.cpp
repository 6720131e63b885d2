// Area-weighted unit vertex normals for the shape index's fits: the whole mesh's, or a band
// of a DEM grid's pixel rows at a time with the same sums (docs/field.md, "Curvatures").
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

#include "shape_index_fit.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/mesh/grid_triangles.hpp"

namespace terrain::field::detail {

namespace {

// Adds triangle t's area-weighted normal (counter-clockwise seen from outside/above) to its
// corners v that take(v) takes, at normals[v - first].
template <class Take>
void add_normal(const TriangleMesh& mesh, const std::array<std::int32_t, 3>& t, std::size_t first,
                std::vector<Vec3>& normals, const Take& take) {
    const auto& p = mesh.positions();
    const Vec3 n = cross(sub(p[t[1]], p[t[0]]), sub(p[t[2]], p[t[0]]));
    for (auto v : t)
        if (take(v))
            for (int k = 0; k < 3; ++k) normals[std::size_t(v) - first][k] += n[k];
}

}  // namespace

// Area-weighted vertex normals. Each vertex's sum is taken in triangle order; a DEM mesh whose
// rows of blocks can be made alone (terrain::detail::rows_of_triangles) sums them on every
// thread by bands of block rows (terrain::detail::add_in_order_by_bands), the sums of one
// pass in order.
std::vector<Vec3> vertex_normals(const TriangleMesh& mesh, const ProgressFn& progress) {
    const terrain::detail::PassProgress summed(progress, 0.3, 0.8, "shape index");
    std::vector<Vec3> normals;  // made a slice at a time: the first touch of a block is slow
    terrain::detail::assign_in_slices(
        normals, mesh.vertex_count(), Vec3{0, 0, 0},
        terrain::detail::PassProgress(progress, 0, 0.3, "shape index"));
    const auto add = [&](const std::array<std::int32_t, 3>& t, auto&& take) {
        add_normal(mesh, t, 0, normals, take);
    };
    if (terrain::detail::rows_of_triangles(mesh)) {
        const std::int64_t W = mesh.grid_width;
        terrain::detail::add_in_order_by_bands(
            mesh.grid_height - 1,
            [&](std::int32_t v) { return mesh.vertex_pixel[std::size_t(v)] / W; },
            [&](int row, const auto& f) { terrain::detail::for_each_row_triangle(mesh, row, f); },
            add, progress, 0.3, 0.8, "shape index");
    } else {
        const std::size_t nt = mesh.triangle_count();
        terrain::detail::for_each_triangle(
            mesh, [&](std::size_t i, const std::array<std::int32_t, 3>& t) {
                summed.at(i, nt);
                add(t, [](std::int32_t) { return true; });
            });
    }
    terrain::detail::parallel_slices(normals.size(), std::size_t{1} << 14, progress, 0.8, 1,
                                     "shape index", [&](const tbb::blocked_range<std::size_t>& r) {
                                         for (std::size_t v = r.begin(); v < r.end(); ++v)
                                             normals[v] = normalized(normals[v]);
                                     });
    return normals;
}

bool normals_by_bands(const TriangleMesh& mesh) {
    return terrain::detail::rows_of_triangles(mesh) && mesh.pinched_vertices == 0 &&
           mesh.vertex_pixel.size() == mesh.vertex_count();
}

// A vertex of pixel row p is a corner only in block rows p - 1 and p: the band's sums take
// block rows r0 - 1 to r1 - 1 through add_in_order_by_bands, as vertex_normals does, adding
// only to the band's vertices, each of whose sums thus runs in triangle order.
void band_normals(const TriangleMesh& mesh, int r0, int r1, Normals& out) {
    const std::size_t W = std::size_t(mesh.grid_width);
    std::int32_t lo = std::numeric_limits<std::int32_t>::max(), hi = -1;
    for (std::size_t p = std::size_t(r0) * W; p < std::size_t(r1) * W; ++p)
        if (const auto v = mesh.pixel_vertex[p]; v >= 0) lo = std::min(lo, v), hi = std::max(hi, v);
    out.first = hi < lo ? 0 : std::size_t(lo);
    out.values.assign(hi < lo ? 0 : std::size_t(hi - lo) + 1, Vec3{0, 0, 0});
    if (out.values.empty()) return;
    const int base = std::max(r0 - 1, 0), end = std::min(r1, mesh.grid_height - 1);
    const auto pixel_row = [&](std::int32_t v) {
        return int(std::size_t(mesh.vertex_pixel[std::size_t(v)]) / W);
    };
    terrain::detail::add_in_order_by_bands(
        end - base, [&](std::int32_t v) { return pixel_row(v) - base; },
        [&](int row, const auto& f) {
            terrain::detail::for_each_row_triangle(mesh, base + row, f);
        },
        [&](const std::array<std::int32_t, 3>& t, const auto& take) {
            add_normal(mesh, t, out.first, out.values, [&](std::int32_t v) {
                const int row = pixel_row(v);
                return row >= r0 && row < r1 && take(v);
            });
        },
        {}, 0, 1, "shape index");
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.values.size(), std::size_t{1} << 14),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i < r.end(); ++i)
                              out.values[i] = normalized(out.values[i]);
                      });
}

}  // namespace terrain::field::detail
