#pragma once
// Private: the triangles of a DEM's grid (METHOD.md s.1), made one row of 2x2 blocks at a
// time. dem_to_mesh makes the mesh's triangles with it, and for_each_triangle makes them
// again for a DEM mesh whose triangles were released after the Reeb graph
// (TriangleMesh::release_triangles), in the same order and with the same corners. Not
// installed.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::detail {

using Triangle = std::array<std::int32_t, 3>;

// Whether the block of four vertices v00 v10 (top) v01 v11 (bottom) is split along its
// top-right to bottom-left diagonal: when it is the shorter in 3-D (ties go to the other).
inline bool split_top_right(const std::vector<std::array<float, 3>>& positions, std::int32_t v00,
                            std::int32_t v10, std::int32_t v01, std::int32_t v11) {
    const auto dist2 = [&](std::int32_t i, std::int32_t j) {
        const auto& p = positions[static_cast<std::size_t>(i)];
        const auto& q = positions[static_cast<std::size_t>(j)];
        const double d[3] = {double(p[0]) - q[0], double(p[1]) - q[1], double(p[2]) - q[2]};
        return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    };
    return !(dist2(v00, v11) <= dist2(v10, v01));
}

// The words of one row of blocks in TriangleMesh::block_diagonals.
inline std::size_t diagonal_words(int width) {
    return (static_cast<std::size_t>(width) + 63) / 64;
}

// The triangles of the blocks between two rows of pixels whose vertices are `top` and
// `bottom` (-1: none), `width` pixels each: two for four vertices, split along the diagonal
// that split(col, v00, v10, v01, v11) names (true: top-right to bottom-left; the shorter in
// 3-D when the mesh is made, split_top_right), one for three, none for fewer, and none
// repeating a vertex (a collapsed pole). With `seam` the last block joins the last column to
// the first. Rows growing southwards and columns eastwards (the geotransform's determinant
// negative) give counter-clockwise triangles seen from above or outside; `flip` swaps their
// last two corners otherwise. emit(const Triangle&) for each, in order.
template <class Split, class Emit>
void block_row_triangles(const std::int32_t* top, const std::int32_t* bottom, int width, bool seam,
                         bool flip, Split&& split, Emit&& emit) {
    const auto put = [&](std::int32_t p, std::int32_t q, std::int32_t r) {
        if (p < 0 || q < 0 || r < 0 || p == q || q == r || p == r) return;
        emit(flip ? Triangle{p, r, q} : Triangle{p, q, r});
    };
    const int blocks = seam ? width : width - 1;
    for (int col = 0; col < blocks; ++col) {
        const int right = col + 1 == width ? 0 : col + 1;
        const std::int32_t v00 = top[col], v10 = top[right], v01 = bottom[col], v11 = bottom[right];
        const int valid = (v00 >= 0) + (v10 >= 0) + (v01 >= 0) + (v11 >= 0);
        if (valid < 3) continue;
        if (valid == 3) {
            if (v00 < 0)
                put(v10, v01, v11);
            else if (v10 < 0)
                put(v00, v01, v11);
            else if (v01 < 0)
                put(v00, v11, v10);
            else
                put(v00, v01, v10);
            continue;
        }
        if (!split(col, v00, v10, v01, v11)) {
            put(v00, v01, v11);
            put(v00, v11, v10);
        } else {
            put(v00, v01, v10);
            put(v10, v01, v11);
        }
    }
}

// The split of the blocks of row `row` as recorded in TriangleMesh::block_diagonals.
inline auto recorded_split(const TriangleMesh& mesh, int row) {
    const std::uint64_t* bits = mesh.block_diagonals.data() +
                                static_cast<std::size_t>(row) * diagonal_words(mesh.grid_width);
    return [bits](int col, std::int32_t, std::int32_t, std::int32_t, std::int32_t) {
        return ((bits[static_cast<unsigned>(col) / 64] >> (static_cast<unsigned>(col) % 64)) & 1) !=
               0;
    };
}

// Whether the triangles of each row of blocks can be made alone, in any order
// (for_each_row_triangle): a DEM mesh whose triangles were released and that has no split
// pinch (whose triangles are patched in by their index in the whole order).
inline bool rows_of_triangles(const TriangleMesh& mesh) {
    return mesh.triangles_released() && mesh.pinch_triangles.empty();
}

// f(triangle) for each triangle of row `row` of blocks (between pixel rows row and row + 1),
// in order; only where rows_of_triangles(mesh).
template <class F>
void for_each_row_triangle(const TriangleMesh& mesh, int row, F&& f) {
    const std::size_t W = static_cast<std::size_t>(mesh.grid_width);
    const std::int32_t* top = mesh.pixel_vertex.data() + static_cast<std::size_t>(row) * W;
    block_row_triangles(top, top + W, mesh.grid_width, mesh.seam_closed, mesh.triangles_flipped,
                        recorded_split(mesh, row), f);
}

// Sums at the corners of a DEM mesh's triangles, each vertex's taken in triangle order, on
// every thread. emit_row(row, f) calls f(triangle) for each triangle of row `row` of blocks
// (0 to rows - 1), in order; add(triangle, take) adds the triangle's share to its corners v
// for which take(v). A vertex of pixel row p (pixel_row(v)) is a corner only in block rows
// p - 1 and p, so bands of 16 block rows add their triangles at once but to their first row
// of vertices, to which each band adds once every band is done (after the band before has
// added its own), going over its first block row again: each vertex's sum runs in triangle
// order, as one pass would. Progress from `begin` to `end` under `message`.
template <class PixelRow, class EmitRow, class Add>
void add_in_order_by_bands(int rows, const PixelRow& pixel_row, const EmitRow& emit_row,
                           const Add& add, const ProgressFn& progress, double begin, double end,
                           std::string_view message) {
    constexpr int kBandRows = 16;
    const int bands = (rows + kBandRows - 1) / kBandRows;
    const double middle = begin + (end - begin) * 0.8;
    for (const bool first_rows : {false, true})
        parallel_slices(
            bands, 1, progress, first_rows ? middle : begin, first_rows ? end : middle, message,
            [&](const tbb::blocked_range<int>& r) {
                for (int band = r.begin(); band < r.end(); ++band) {
                    const int first = band * kBandRows;
                    if (first_rows) {
                        if (band > 0)
                            emit_row(first, [&](const Triangle& t) {
                                add(t, [&](std::int32_t v) { return pixel_row(v) == first; });
                            });
                        continue;
                    }
                    for (int row = first; row < std::min(rows, first + kBandRows); ++row)
                        emit_row(row, [&](const Triangle& t) {
                            add(t,
                                [&](std::int32_t v) { return band == 0 || pixel_row(v) != first; });
                        });
                }
            });
}

// f(index, triangle) for each triangle of `mesh` in order: its stored triangles, or for a
// DEM mesh whose triangles were released, the same made again from the grid (with the
// diagonals recorded when it was made: no position is read).
template <class F>
void for_each_triangle(const TriangleMesh& mesh, F&& f) {
    if (!mesh.triangles_released()) {
        const auto& triangles = mesh.triangles();
        for (std::size_t i = 0; i < triangles.size(); ++i) f(i, triangles[i]);
        return;
    }
    const std::size_t W = static_cast<std::size_t>(mesh.grid_width);
    const auto& patches = mesh.pinch_triangles;
    std::size_t index = 0, patch = 0;
    for (int row = 0; row + 1 < mesh.grid_height; ++row) {
        const std::int32_t* top = mesh.pixel_vertex.data() + static_cast<std::size_t>(row) * W;
        block_row_triangles(top, top + W, mesh.grid_width, mesh.seam_closed, mesh.triangles_flipped,
                            recorded_split(mesh, row), [&](const Triangle& t) {
                                if (patch < patches.size() && patches[patch].first == index)
                                    f(index, patches[patch++].second);
                                else
                                    f(index, t);
                                ++index;
                            });
    }
}

// add(triangle) for each triangle of `mesh`, where what add gathers at a triangle's corners does
// not depend on the order of the triangles. A DEM mesh whose rows of blocks can be made alone
// (rows_of_triangles) goes in bands of rows in parallel: a vertex's triangles lie in the two
// rows of blocks around its row of pixels, so bands whose rows are at least two apart touch
// no common vertex. First each band's rows but its last, then the last rows; add is called
// from several threads at once, never for two triangles with a common corner. Other meshes go
// in order (for_each_triangle). Progress from `begin` to `end` under `message`.
template <class Add>
void for_each_triangle_by_bands(const TriangleMesh& mesh, const ProgressFn& progress, double begin,
                                double end, std::string_view message, Add&& add) {
    constexpr int kBandRows = 8;
    if (!rows_of_triangles(mesh) || mesh.grid_height <= 2 * kBandRows) {
        const PassProgress pass(progress, begin, end, message);
        const std::size_t n = mesh.triangle_count();
        for_each_triangle(mesh, [&](std::size_t i, const Triangle& t) {
            pass.at(i, n);
            add(t);
        });
        return;
    }
    const int rows = mesh.grid_height - 1, bands = (rows + kBandRows - 1) / kBandRows;
    const double middle = begin + (end - begin) * (kBandRows - 1) / kBandRows;
    for (const bool last : {false, true})
        parallel_slices(bands, 1, progress, last ? middle : begin, last ? end : middle, message,
                        [&](const tbb::blocked_range<int>& r) {
                            for (int band = r.begin(); band < r.end(); ++band) {
                                const int stop = std::min(rows, (band + 1) * kBandRows);
                                for (int row = last ? stop - 1 : band * kBandRows;
                                     row < stop - !last; ++row)
                                    for_each_row_triangle(mesh, row, add);
                            }
                        });
}

}  // namespace terrain::detail
