// Vertex areas: one third of each incident triangle's, summed in triangle order, on every
// thread by bands of block rows on a DEM mesh (docs/mesh.md).
#include "vertex_areas.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <ranges>
#include <vector>

#include "terrain/internal/mesh/grid_triangles.hpp"

namespace terrain::detail {

namespace {

double triangle_area(const TriangleMesh& m, const std::array<std::int32_t, 3>& t) {
    const auto& a = m.positions()[t[0]];
    const auto& b = m.positions()[t[1]];
    const auto& c = m.positions()[t[2]];
    const double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
    const double v[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                         u[0] * v[1] - u[1] * v[0]};
    return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

// set_grid_vertex_areas's sums for a DEM mesh whose vertices each have a pixel of their own
// (no split pinch): the same additions in the same order, each vertex's in triangle order, but
// in doubles for a band's rows only, written out as floats once they are whole. A whole array
// of doubles beside the floats was 8 bytes a pixel more at the mesh's peak. Bands of 16 block
// rows on every thread add their triangles to their pixel rows but the first; the last row's
// sums, still partial, wait in `seam` for the next band, which adds its first block row to
// them once every band is done.
// emit_row(row, f) calls f(triangle) for each triangle of block row `row`, in order.
template <class EmitRow>
void add_areas_by_bands(TriangleMesh& mesh, int rows, const EmitRow& emit_row,
                        const ProgressFn& progress, double begin, double end) {
    const std::size_t W = static_cast<std::size_t>(mesh.grid_width);
    constexpr int kBandRows = 16;
    const int bands = (rows + kBandRows - 1) / kBandRows;
    const double zeroed = begin + (end - begin) * 0.1, middle = begin + (end - begin) * 0.8;
    detail::assign_in_slices(mesh.vertex_areas, mesh.positions().size(), 0.0f,
                             detail::PassProgress(progress, begin, zeroed, "mesh"));
    const auto pixel_of = [&](std::int32_t v) {
        return static_cast<std::size_t>(mesh.vertex_pixel[std::size_t(v)]);
    };
    // f(pixel, third) for each corner of block row `row`'s triangles, in order.
    const auto corners = [&](int row, const auto& f) {
        emit_row(row, [&](const std::array<std::int32_t, 3>& t) {
            const double third = triangle_area(mesh, t) / 3.0;
            for (const auto v : t) f(pixel_of(v), third);
        });
    };
    // Pixel row `row`'s sums (W doubles from `sums`) to its vertices.
    const auto put_row = [&](std::size_t row, const double* sums) {
        for (std::size_t col = 0; col < W; ++col) {
            const std::size_t p = row * W + col;
            const std::int32_t v = mesh.pixel_vertex[p];
            if (v >= 0 && pixel_of(v) == p)
                mesh.vertex_areas[std::size_t(v)] = static_cast<float>(sums[col]);
        }
    };
    std::vector<double> seam(std::size_t(bands) * W, 0.0);  // band b's first row, from b - 1
    detail::parallel_slices(
        bands, 1, progress, zeroed, middle, "mesh", [&](const tbb::blocked_range<int>& r) {
            std::vector<double> sums;  // pixel rows first to last of the band
            for (int band = r.begin(); band < r.end(); ++band) {
                const int first = band * kBandRows, last = std::min(rows, first + kBandRows);
                sums.assign(std::size_t(last - first + 1) * W, 0.0);
                for (int row = first; row < last; ++row)
                    corners(row, [&](std::size_t p, double third) {
                        const std::size_t at = p - std::size_t(first) * W;
                        if (band == 0 || at >= W) sums[at] += third;
                    });
                for (int row = band == 0 ? first : first + 1; row < last; ++row)
                    put_row(std::size_t(row), &sums[std::size_t(row - first) * W]);
                const double* tail = &sums[std::size_t(last - first) * W];
                if (band + 1 == bands)
                    put_row(std::size_t(last), tail);  // the grid's last row
                else
                    std::copy(tail, tail + W, &seam[std::size_t(band + 1) * W]);
            }
        });
    detail::parallel_slices(bands, 1, progress, middle, end, "mesh",
                            [&](const tbb::blocked_range<int>& r) {
                                for (int band = std::max(r.begin(), 1); band < r.end(); ++band) {
                                    const std::size_t first = std::size_t(band) * kBandRows;
                                    double* sums = &seam[std::size_t(band) * W];
                                    corners(band * kBandRows, [&](std::size_t p, double third) {
                                        if (p / W == first) sums[p % W] += third;
                                    });
                                    put_row(first, sums);
                                }
                            });
}

}  // namespace

// Vertex areas: one third of each incident triangle (serial: the same sums every run).
void set_vertex_areas(TriangleMesh& mesh, const detail::PassProgress& areas) {
    const std::size_t nt = mesh.triangles().size();
    std::vector<double> area(mesh.positions().size(), 0.0);
    for (std::size_t i = 0; i < nt; ++i) {
        areas.at(i, nt);
        const auto& t = mesh.triangles()[i];
        const double third = triangle_area(mesh, t) / 3.0;
        for (int k = 0; k < 3; ++k) area[t[k]] += third;
    }
    mesh.vertex_areas.assign(area.begin(), area.end());
}

// The same sums for a DEM mesh, on every thread, by bands of block rows
// (add_in_order_by_bands): its triangles come in rows of blocks, a vertex of pixel row p a
// corner only in block rows p - 1 and p. False (nothing done) when a triangle is not so.
bool set_grid_vertex_areas(TriangleMesh& mesh, const ProgressFn& progress, double begin,
                           double end) {
    const std::int64_t W = mesh.grid_width;
    const int rows = mesh.grid_height - 1;
    // Triangles released (dem_to_mesh's release_triangles): made again row by row from the
    // grid, in the order they had, which has no split pinch.
    if (detail::rows_of_triangles(mesh)) {
        add_areas_by_bands(
            mesh, rows,
            [&](int row, const auto& f) { detail::for_each_row_triangle(mesh, row, f); }, progress,
            begin, end);
        return true;
    }
    const auto& triangles = mesh.triangles();
    const std::size_t nt = triangles.size();
    const auto pixel_row = [&](std::int32_t v) {
        return static_cast<std::int64_t>(mesh.vertex_pixel[std::size_t(v)]) / W;
    };
    const auto block_row = [&](std::size_t i) {
        const auto& t = triangles[i];
        return std::min({pixel_row(t[0]), pixel_row(t[1]), pixel_row(t[2])});
    };
    // Block rows in order, each corner on its block row or the next.
    std::atomic<bool> grid_like{rows > 0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nt, std::size_t{1} << 14),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i < r.end(); ++i) {
                              const std::int64_t b = block_row(i);
                              bool ok = b < rows && (i == 0 || block_row(i - 1) <= b);
                              for (const auto v : triangles[i]) ok = ok && pixel_row(v) - b <= 1;
                              if (!ok) grid_like = false;
                          }
                      });
    if (!grid_like) return false;
    // Each block row's first triangle.
    std::vector<std::size_t> row_first(std::size_t(rows) + 1, nt);
    for (int row = 0; row < rows; ++row)
        row_first[std::size_t(row)] =
            *std::ranges::partition_point(std::views::iota(std::size_t{0}, nt),
                                          [&](std::size_t i) { return block_row(i) < row; });
    if (mesh.pinched_vertices == 0 &&
        mesh.pixel_vertex.size() == std::size_t(W) * std::size_t(mesh.grid_height)) {
        add_areas_by_bands(
            mesh, rows,
            [&](int row, const auto& f) {
                for (std::size_t i = row_first[std::size_t(row)];
                     i < row_first[std::size_t(row) + 1]; ++i)
                    f(triangles[i]);
            },
            progress, begin, end);
        return true;
    }
    std::vector<double> area(mesh.positions().size(), 0.0);
    detail::add_in_order_by_bands(
        rows, pixel_row,
        [&](int row, const auto& f) {
            for (std::size_t i = row_first[std::size_t(row)]; i < row_first[std::size_t(row) + 1];
                 ++i)
                f(triangles[i]);
        },
        [&](const std::array<std::int32_t, 3>& t, auto&& take) {
            const double third = triangle_area(mesh, t) / 3.0;
            for (const auto v : t)
                if (take(v)) area[std::size_t(v)] += third;
        },
        progress, begin, end, "mesh");
    mesh.vertex_areas.assign(area.begin(), area.end());
    return true;
}

}  // namespace terrain::detail
