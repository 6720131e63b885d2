#include "terrain/mesh/triangle_mesh.hpp"
#include "../core/disjoint_sets.hpp"
#include "../core/pass_progress.hpp"
#include "../core/ranked_bits.hpp"
#include "../core/release.hpp"
#include "grid_triangles.hpp"
#include "terrain/core/error.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numeric>
#include <ranges>
#include <string>

namespace terrain {

const char* to_string(MeshFrame frame) {
    switch (frame) {
        case MeshFrame::body:
            return "body";
        case MeshFrame::map:
            return "map";
        default:
            return "file";
    }
}

std::size_t TriangleMesh::memory_bytes() const {
    return positions.capacity() * sizeof(positions[0]) +
           triangles.capacity() * sizeof(triangles[0]) + vertex_areas.capacity() * sizeof(float) +
           neighbor_offsets.capacity() * sizeof(std::int32_t) +
           neighbors.capacity() * sizeof(std::int32_t) +
           vertex_pixel.capacity() * sizeof(std::int32_t) +
           pixel_vertex.capacity() * sizeof(std::int32_t) + neighbor_directions.capacity() +
           irregular_vertices.capacity() * sizeof(std::int32_t) +
           irregular_offsets.capacity() * sizeof(std::uint32_t) +
           irregular_neighbors.capacity() * sizeof(std::int32_t) +
           pinch_triangles.capacity() * sizeof(pinch_triangles[0]) +
           block_diagonals.capacity() * sizeof(std::uint64_t) +
           uniform_ranges.capacity() * sizeof(uniform_ranges[0]);
}

void TriangleMesh::release_adjacency() {
    detail::release(neighbor_offsets);
    detail::release(neighbors);
    detail::release(neighbor_directions);
    detail::release(irregular_vertices);
    detail::release(irregular_offsets);
    detail::release(irregular_neighbors);
    detail::release(uniform_ranges);
    grid_edges = 0;
}

bool TriangleMesh::grid_describes_it() const {
    return frame != MeshFrame::file && grid_width >= 1 && grid_height >= 1 &&
           vertex_pixel.size() == vertex_count() &&
           pixel_vertex.size() == std::size_t(grid_width) * std::size_t(grid_height) &&
           block_diagonals.size() ==
               std::size_t(grid_height - 1) * detail::diagonal_words(grid_width);
}

bool TriangleMesh::triangles_releasable() const {
    return !triangles.empty() && grid_describes_it();
}

bool TriangleMesh::release_triangles() {
    if (triangles_released()) return true;
    if (!triangles_releasable()) return false;
    released_triangles_ = triangles.size();
    detail::release(triangles);
    return true;
}

void TriangleMesh::restore_triangles() {
    if (!triangles_released()) return;
    std::vector<std::array<std::int32_t, 3>> made;
    made.reserve(released_triangles_);
    detail::for_each_triangle(*this, [&](std::size_t, const auto& t) { made.push_back(t); });
    if (made.size() != released_triangles_)
        throw Error("mesh", "internal: the triangles made again are not those released");
    triangles = std::move(made);
    released_triangles_ = 0;
}

bool TriangleMesh::release_positions() {
    if (positions_released()) return true;
    if (positions.empty() || !grid_describes_it()) return false;
    released_vertices_ = positions.size();
    detail::release(positions);
    return true;
}

void TriangleMesh::set_restored_positions(std::vector<std::array<float, 3>>&& placed) {
    if (!positions_released() || placed.size() != released_vertices_)
        throw Error("mesh", "internal: the positions placed again are not one a vertex");
    positions = std::move(placed);
    released_vertices_ = 0;
}

VertexNeighbors TriangleMesh::irregular_neighbors_of(std::size_t v) const {
    const auto it = std::lower_bound(irregular_vertices.begin(), irregular_vertices.end(),
                                     static_cast<std::int32_t>(v));
    const auto i = static_cast<std::size_t>(it - irregular_vertices.begin());
    VertexNeighbors out;
    out.list_ = irregular_neighbors.data() + irregular_offsets[i];
    out.size_ = irregular_offsets[i + 1] - irregular_offsets[i];
    return out;
}

namespace {

double triangle_area(const TriangleMesh& m, const std::array<std::int32_t, 3>& t) {
    const auto& a = m.positions[t[0]];
    const auto& b = m.positions[t[1]];
    const auto& c = m.positions[t[2]];
    const double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
    const double v[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                         u[0] * v[1] - u[1] * v[0]};
    return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

}  // namespace

void set_positions(TriangleMesh& mesh, const std::vector<std::array<double, 3>>& points,
                   const ProgressFn& progress) {
    const std::size_t n = points.size();
    // The bounds of slices on every thread, joined in order: each slice keeps the first of
    // equal values (std::min and std::max keep their first argument), as one pass would.
    constexpr std::size_t kSlices = 64;
    struct Bounds {
        std::array<double, 3> lo, hi;
    };
    std::vector<Bounds> slices(kSlices);
    const auto slice_begin = [n](std::size_t s) { return n * s / kSlices; };
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, kSlices, 1), [&](const auto& r) {
        for (std::size_t s = r.begin(); s < r.end(); ++s) {
            Bounds& b = slices[s];
            b.lo.fill(std::numeric_limits<double>::infinity());
            b.hi.fill(-std::numeric_limits<double>::infinity());
            for (std::size_t v = slice_begin(s); v < slice_begin(s + 1); ++v)
                for (int k = 0; k < 3; ++k)
                    b.lo[k] = std::min(b.lo[k], points[v][k]),
                    b.hi[k] = std::max(b.hi[k], points[v][k]);
        }
    });
    report_progress(progress, 0.3, "mesh");
    std::array<double, 3> lo, hi;
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    for (const auto& b : slices)
        for (int k = 0; k < 3; ++k)
            lo[k] = std::min(lo[k], b.lo[k]), hi[k] = std::max(hi[k], b.hi[k]);
    for (int k = 0; k < 3; ++k) mesh.origin[k] = points.empty() ? 0.0 : 0.5 * (lo[k] + hi[k]);
    detail::assign_in_slices(mesh.positions, n, std::array<float, 3>{},
                             detail::PassProgress(progress, 0.3, 0.6, "mesh"));
    detail::parallel_slices(n, std::size_t{4096}, progress, 0.6, 1, "mesh",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t v = r.begin(); v < r.end(); ++v)
                                    for (int k = 0; k < 3; ++k)
                                        mesh.positions[v][k] =
                                            static_cast<float>(points[v][k] - mesh.origin[k]);
                            });
}

namespace {

// Refuses a mesh whose per-corner lists would pass the 32-bit offsets that index them.
void check_adjacency_size(std::uint64_t entries, const char* what) {
    if (entries > std::uint64_t{UINT32_MAX})
        throw Error("mesh", "the mesh has " + std::to_string(entries) + " " + what +
                                ", more than 32-bit offsets can index: too large");
}

}  // namespace

namespace {

// Sorts each of the `count` lists lists[offsets[i] .. offsets[i + 1]) and drops its repeats,
// packing them one after the other from the front of `lists`; packed(i, end) is told where
// list i now ends. Returns the packed length.
template <class Packed>
std::size_t pack_sorted_lists(std::vector<std::int32_t>& lists,
                              const std::vector<std::uint32_t>& offsets, std::size_t count,
                              Packed&& packed) {
    std::size_t write = 0;
    for (std::size_t i = 0; i < count; ++i) {
        auto begin = lists.begin() + offsets[i], end = lists.begin() + offsets[i + 1];
        std::sort(begin, end);
        end = std::unique(begin, end);
        for (auto it = begin; it != end; ++it) lists[write++] = *it;
        packed(i, write);
    }
    return write;
}

// What gather(i, out) pushes into `out` for each triangle i (or each row of blocks i), by 64
// slices of them on every thread: each slice's items in triangle order, so that reading the
// slices one after the other reads them in the order of one pass.
template <class T, class Gather>
std::vector<std::vector<T>> gather_by_slices(std::size_t nt, const Gather& gather) {
    constexpr std::size_t kSlices = 64;
    std::vector<std::vector<T>> out(kSlices);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, kSlices, 1), [&](const auto& r) {
        for (std::size_t sl = r.begin(); sl < r.end(); ++sl)
            for (std::size_t i = nt * sl / kSlices; i < nt * (sl + 1) / kSlices; ++i)
                gather(i, out[sl]);
    });
    return out;
}

// Vertex areas: one third of each incident triangle (serial: the same sums every run).
void set_vertex_areas(TriangleMesh& mesh, const detail::PassProgress& areas) {
    const std::size_t nt = mesh.triangles.size();
    std::vector<double> area(mesh.positions.size(), 0.0);
    for (std::size_t i = 0; i < nt; ++i) {
        areas.at(i, nt);
        const auto& t = mesh.triangles[i];
        const double third = triangle_area(mesh, t) / 3.0;
        for (int k = 0; k < 3; ++k) area[t[k]] += third;
    }
    mesh.vertex_areas.assign(area.begin(), area.end());
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
    detail::assign_in_slices(mesh.vertex_areas, mesh.positions.size(), 0.0f,
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

// The same sums for a DEM mesh, on every thread, by bands of block rows
// (add_in_order_by_bands): its triangles come in rows of blocks, a vertex of pixel row p a
// corner only in block rows p - 1 and p. False (nothing done) when a triangle is not so.
bool set_grid_vertex_areas(TriangleMesh& mesh, const ProgressFn& progress, double begin,
                           double end) {
    const std::int64_t W = mesh.grid_width;
    const std::size_t nt = mesh.triangles.size();
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
    const auto pixel_row = [&](std::int32_t v) {
        return static_cast<std::int64_t>(mesh.vertex_pixel[std::size_t(v)]) / W;
    };
    const auto block_row = [&](std::size_t i) {
        const auto& t = mesh.triangles[i];
        return std::min({pixel_row(t[0]), pixel_row(t[1]), pixel_row(t[2])});
    };
    // Block rows in order, each corner on its block row or the next.
    std::atomic<bool> grid_like{rows > 0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nt, std::size_t{1} << 14),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i < r.end(); ++i) {
                              const std::int64_t b = block_row(i);
                              bool ok = b < rows && (i == 0 || block_row(i - 1) <= b);
                              for (const auto v : mesh.triangles[i])
                                  ok = ok && pixel_row(v) - b <= 1;
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
                    f(mesh.triangles[i]);
            },
            progress, begin, end);
        return true;
    }
    std::vector<double> area(mesh.positions.size(), 0.0);
    detail::add_in_order_by_bands(
        rows, pixel_row,
        [&](int row, const auto& f) {
            for (std::size_t i = row_first[std::size_t(row)]; i < row_first[std::size_t(row) + 1];
                 ++i)
                f(mesh.triangles[i]);
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

}  // namespace

void finish_mesh(TriangleMesh& mesh, const ProgressFn& progress) {
    const std::size_t n = mesh.positions.size();
    // Its passes: areas (0 to 0.25), the corners' lists (counted, made, filled: to 0.6),
    // sorted (to 0.9), copied at their size (to 1).
    const detail::PassProgress counts(progress, 0.25, 0.35, "mesh"),
        lists(progress, 0.45, 0.6, "mesh");
    const std::size_t nt = mesh.triangles.size();
    mesh.release_adjacency();
    set_vertex_areas(mesh, detail::PassProgress(progress, 0, 0.25, "mesh"));
    report_progress(progress, 0.25, "mesh");

    // CSR adjacency from the triangles' edges, each list sorted and without repeats. Before
    // the repeats go there are two entries per triangle corner (12 per vertex of a grid,
    // past 2^31 at 179 M vertices): 32-bit unsigned offsets, checked.
    check_adjacency_size(6 * std::uint64_t{mesh.triangles.size()}, "triangle corners");
    std::vector<std::uint32_t> offsets(n + 1, 0);
    for (std::size_t i = 0; i < nt; ++i) {
        counts.at(i, nt);
        for (int k = 0; k < 3; ++k) offsets[mesh.triangles[i][k] + 1] += 2;
    }
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    std::vector<std::int32_t> all;
    detail::assign_in_slices(all, offsets.back(), 0,
                             detail::PassProgress(progress, 0.35, 0.45, "mesh"));
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t i = 0; i < nt; ++i) {
        lists.at(i, nt);
        const auto& t = mesh.triangles[i];
        for (int k = 0; k < 3; ++k) {
            all[fill[t[k]]++] = t[(k + 1) % 3];
            all[fill[t[k]]++] = t[(k + 2) % 3];
        }
    }
    detail::release(fill);
    report_progress(progress, 0.6, "mesh");
    mesh.neighbor_offsets.assign(n + 1, 0);
    const detail::PassProgress sorted(progress, 0.6, 0.9, "mesh");
    const std::size_t write =
        pack_sorted_lists(all, offsets, n, [&](std::size_t v, std::size_t end) {
            if (end > std::size_t{INT32_MAX})
                throw Error("mesh", "the mesh has more than 2^31 vertex neighbours (" +
                                        std::to_string(n) + " vertices): too large");
            mesh.neighbor_offsets[v + 1] = static_cast<std::int32_t>(end);
            sorted.at(v, n);
        });
    detail::copy_in_slices(mesh.neighbors, all.data(), write,
                           detail::PassProgress(progress, 0.9, 1, "mesh"));
}

namespace {

// The longest runs of rows whose pixels each have their own vertex, numbered as the pixels
// (vertex = pixel + the same shift along the run), as vertex ranges less two rows at each end:
// any pixel within one row and one column of a vertex there is in the run, so its vertex is
// the vertex's plus the pixels' offset (TriangleMesh::uniform_ranges).
std::vector<std::array<std::int32_t, 2>> uniform_ranges(const TriangleMesh& mesh) {
    const std::int64_t W = mesh.grid_width, H = mesh.grid_height;
    struct Run {
        std::int64_t first_row, rows, shift;
    };
    std::vector<Run> runs;
    for (std::int64_t r = 0; r < H; ++r) {
        const std::int64_t p0 = r * W,
                           shift = std::int64_t(mesh.pixel_vertex[std::size_t(p0)]) - p0;
        bool dense = mesh.pixel_vertex[std::size_t(p0)] >= 0;
        for (std::int64_t c = 1; dense && c < W; ++c)
            dense = std::int64_t(mesh.pixel_vertex[std::size_t(p0 + c)]) == p0 + c + shift;
        if (!dense) continue;
        if (!runs.empty() && runs.back().first_row + runs.back().rows == r &&
            runs.back().shift == shift)
            ++runs.back().rows;
        else
            runs.push_back({r, 1, shift});
    }
    std::erase_if(runs, [](const Run& run) { return run.rows < 5; });
    std::stable_sort(runs.begin(), runs.end(),
                     [](const Run& a, const Run& b) { return a.rows > b.rows; });
    if (runs.size() > TriangleMesh::kUniformRanges) runs.resize(TriangleMesh::kUniformRanges);
    std::vector<std::array<std::int32_t, 2>> out;
    for (const auto& run : runs)
        out.push_back({static_cast<std::int32_t>((run.first_row + 2) * W + run.shift),
                       static_cast<std::int32_t>((run.first_row + run.rows - 2) * W + run.shift)});
    std::sort(out.begin(), out.end());
    return out;
}

}  // namespace

void finish_grid_mesh(TriangleMesh& mesh, const ProgressFn& progress) {
    const std::int64_t W = mesh.grid_width;
    const std::size_t n = mesh.positions.size(), nt = mesh.triangles.size();
    // Triangles released (dem_to_mesh's release_triangles, no split pinch): each pass walks
    // them from the grid, a row of blocks at a time.
    const bool by_rows = detail::rows_of_triangles(mesh);
    if (W < 3 || mesh.vertex_pixel.size() != n ||
        mesh.pixel_vertex.size() != std::size_t(mesh.grid_width) * std::size_t(mesh.grid_height)) {
        finish_mesh(mesh, progress);
        return;
    }
    // Its passes: areas (0 to 0.3), the directions (made, set: to 0.6), checked (to 0.8), the
    // irregular vertices' lists (0.9 to 1).
    mesh.release_adjacency();
    if (!set_grid_vertex_areas(mesh, progress, 0, 0.3))
        set_vertex_areas(mesh, detail::PassProgress(progress, 0, 0.3, "mesh"));
    mesh.direction_offsets = {-W - 1, -W, -W + 1, -1, 1, W - 1, W, W + 1};
    mesh.uniform_ranges = uniform_ranges(mesh);
    // The direction of the pixel dp away (-1: not one of the 8 around, or across the seam,
    // which comes out of order and is left to the explicit lists).
    const auto direction = [W](std::int64_t dp) -> int {
        if (dp >= -W - 1 && dp <= -W + 1) return static_cast<int>(dp + W + 1);
        if (dp == -1 || dp == 1) return dp < 0 ? 3 : 4;
        if (dp >= W - 1 && dp <= W + 1) return static_cast<int>(dp - W + 6);
        return -1;
    };
    // Every edge a -> b of a triangle sets a's bit towards b's pixel, or marks a irregular
    // when b is not the vertex of a pixel around a's (a pole, a pinch's copy).
    std::vector<std::uint8_t> bits, irregular;
    detail::assign_in_slices(bits, n, std::uint8_t{0},
                             detail::PassProgress(progress, 0.3, 0.35, "mesh"));
    irregular.assign(n, 0);
    for (const auto pole : mesh.pole_vertices)
        if (pole >= 0) irregular[std::size_t(pole)] = 1;
    // (On every thread: a vertex's bits are an OR and its mark a flag, the same in any order.)
    const auto mark = [&](const std::array<std::int32_t, 3>& t) {
        for (int k = 0; k < 3; ++k) {
            const auto a = static_cast<std::size_t>(t[k]);
            const std::int64_t pa = mesh.vertex_pixel[a];
            for (int j = 1; j < 3; ++j) {
                const std::int32_t b = t[(k + j) % 3];
                const std::int64_t pb = mesh.vertex_pixel[std::size_t(b)];
                const int d = direction(pb - pa);
                if (d < 0 || mesh.pixel_vertex[std::size_t(pb)] != b)
                    std::atomic_ref<std::uint8_t>(irregular[a]).store(1, std::memory_order_relaxed);
                else
                    std::atomic_ref<std::uint8_t>(bits[a]).fetch_or(
                        static_cast<std::uint8_t>(1u << d), std::memory_order_relaxed);
            }
        }
    };
    if (by_rows)
        detail::for_each_triangle_by_bands(mesh, progress, 0.35, 0.6, "mesh", mark);
    else
        detail::parallel_slices(nt, std::size_t{4096}, progress, 0.35, 0.6, "mesh",
                                [&](const tbb::blocked_range<std::size_t>& r) {
                                    for (std::size_t i = r.begin(); i < r.end(); ++i)
                                        mark(mesh.triangles[i]);
                                });
    // A vertex is regular when its neighbours, read off the grid in the directions' order,
    // come in increasing order (not so across the seam, or next to a pinch's copy).
    mesh.neighbor_directions = std::move(bits);
    std::atomic<std::uint64_t> regular_degrees{0};
    detail::parallel_slices(
        n, std::size_t{4096}, progress, 0.6, 0.8, "mesh",
        [&](const tbb::blocked_range<std::size_t>& r) {
            std::uint64_t sum = 0;
            for (std::size_t v = r.begin(); v < r.end(); ++v) {
                if (irregular[v]) continue;
                const auto nb = mesh.neighbors_of(v);
                if (std::adjacent_find(nb.begin(), nb.end(), std::greater_equal<>()) != nb.end())
                    irregular[v] = 1;
                else
                    sum += nb.size();
            }
            regular_degrees += sum;
        });
    // The irregular vertices' lists, from their triangles.
    for (std::size_t v = 0; v < n; ++v)
        if (irregular[v]) {
            mesh.neighbor_directions[v] = 0;
            mesh.irregular_vertices.push_back(static_cast<std::int32_t>(v));
        }
    const auto rank = [&](std::int32_t v) {
        return static_cast<std::size_t>(
            std::lower_bound(mesh.irregular_vertices.begin(), mesh.irregular_vertices.end(), v) -
            mesh.irregular_vertices.begin());
    };
    const std::size_t ni = mesh.irregular_vertices.size();
    // Their corners (rank, the two other corners), gathered by slices of triangles on every
    // thread in triangle order within each, then listed slice by slice: the order of one pass.
    const auto gather = [&](const std::array<std::int32_t, 3>& t, auto& out) {
        for (int k = 0; k < 3; ++k)
            if (irregular[std::size_t(t[k])])
                out.push_back(
                    {static_cast<std::int32_t>(rank(t[k])), t[(k + 1) % 3], t[(k + 2) % 3]});
    };
    auto corners = by_rows
                       ? gather_by_slices<std::array<std::int32_t, 3>>(
                             std::size_t(mesh.grid_height - 1),
                             [&](std::size_t row, auto& out) {
                                 detail::for_each_row_triangle(
                                     mesh, int(row), [&](const auto& t) { gather(t, out); });
                             })
                       : gather_by_slices<std::array<std::int32_t, 3>>(
                             nt, [&](std::size_t i, auto& out) { gather(mesh.triangles[i], out); });
    report_progress(progress, 0.95, "mesh");
    std::vector<std::uint32_t> offsets(ni + 1, 0);
    for (const auto& list : corners)
        for (const auto& c : list) offsets[std::size_t(c[0]) + 1] += 2;
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    check_adjacency_size(offsets.back(), "corners at irregular vertices");
    std::vector<std::int32_t> lists(offsets.back(), 0);
    {
        std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
        for (auto& list : corners) {
            for (const auto& c : list) {
                lists[fill[std::size_t(c[0])]++] = c[1];
                lists[fill[std::size_t(c[0])]++] = c[2];
            }
            detail::release(list);
        }
    }
    detail::release(irregular);
    mesh.irregular_offsets.assign(ni + 1, 0);
    const std::size_t write =
        pack_sorted_lists(lists, offsets, ni, [&](std::size_t i, std::size_t end) {
            mesh.irregular_offsets[i + 1] = static_cast<std::uint32_t>(end);
        });
    lists.resize(write);
    mesh.irregular_neighbors = std::move(lists);
    mesh.irregular_neighbors.shrink_to_fit();
    mesh.grid_edges = static_cast<std::size_t>((regular_degrees.load() + write) / 2);
}

std::vector<std::uint32_t> first_edge_slots(const TriangleMesh& mesh) {
    const std::size_t n = mesh.vertex_count();
    std::vector<std::uint32_t> first(n + 1, 0);
    for (std::size_t v = 0; v < n; ++v) {
        first[v + 1] = first[v] + static_cast<std::uint32_t>(mesh.degree(v));
        if (first[v + 1] > std::uint32_t{INT32_MAX})
            throw Error("mesh", "the mesh has more than 2^31 directed edges: too large");
    }
    return first;
}

double mean_vertex_area(const TriangleMesh& mesh) {
    if (mesh.vertex_areas.empty()) return 0;
    double total = 0;
    for (const float a : mesh.vertex_areas) total += a;
    return total / double(mesh.vertex_areas.size());
}

MeshTopology mesh_topology(const TriangleMesh& mesh) {
    if (!mesh.grid_adjacency() && mesh.neighbor_offsets.size() != mesh.vertex_count() + 1) {
        TriangleMesh finished = mesh;  // no adjacency yet
        finish_mesh(finished);
        return mesh_topology(finished);
    }
    MeshTopology topo;
    topo.vertices = mesh.vertex_count();
    topo.faces = mesh.triangle_count();
    const auto first = first_edge_slots(mesh);
    const auto slot = [&](std::int32_t a, std::int32_t b) {
        const auto nb = mesh.neighbors_of(std::size_t(a));
        return first[std::size_t(a)] +
               static_cast<std::uint64_t>(std::lower_bound(nb.begin(), nb.end(), b) - nb.begin());
    };
    // Each edge (a < b) counts its triangles at the slot a -> b.
    // (Triangles through for_each_triangle: a DEM mesh may have released them.)
    using Corners = std::array<std::int32_t, 3>;
    std::vector<std::uint8_t> uses(first.back(), 0);
    detail::for_each_triangle(mesh, [&](std::size_t, const Corners& t) {
        for (int k = 0; k < 3; ++k) {
            const auto s = slot(std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]));
            uses[s] = static_cast<std::uint8_t>(std::min(uses[s] + 1, 3));
        }
    });
    detail::DisjointSets<std::uint32_t> sets(topo.vertices);
    // Boundary loops: components of the graph of boundary edges.
    std::vector<std::uint32_t> boundary_vertices;
    for (std::size_t v = 0; v < topo.vertices; ++v) {
        const auto nb = mesh.neighbors_of(v);
        for (std::size_t i = 0; i < nb.size(); ++i) {
            const auto w = static_cast<std::size_t>(nb[i]);
            if (w <= v) continue;
            ++topo.edges;
            if (uses[first[v] + i] != 1) continue;
            ++topo.boundary_edges;
            boundary_vertices.push_back(static_cast<std::uint32_t>(v));
            sets.unite(static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(v));
        }
    }
    for (auto& v : boundary_vertices) v = sets.find(v);
    std::sort(boundary_vertices.begin(), boundary_vertices.end());
    topo.boundary_loops =
        static_cast<std::size_t>(std::unique(boundary_vertices.begin(), boundary_vertices.end()) -
                                 boundary_vertices.begin());
    // Components by triangles.
    sets.reset(topo.vertices);
    std::vector<char> used(topo.vertices, 0);
    detail::for_each_triangle(mesh, [&](std::size_t, const Corners& t) {
        for (int k = 1; k < 3; ++k) sets.unite(std::uint32_t(t[k]), std::uint32_t(t[0]));
        for (int k = 0; k < 3; ++k) used[t[k]] = 1;
    });
    for (std::size_t v = 0; v < topo.vertices; ++v)
        if (used[v] && sets.is_root(std::uint32_t(v))) ++topo.components;
    topo.euler_characteristic =
        std::int64_t(topo.vertices) - std::int64_t(topo.edges) + std::int64_t(topo.faces);
    return topo;
}

// Fans around each vertex: triangles incident to v joined when they share an edge at v.
// Every fan after the largest (ties: the one holding the lowest triangle index) gets a copy
// of v. Returns the number of vertices split.
std::size_t split_pinched_vertices(TriangleMesh& mesh, std::int32_t* first_pinched,
                                   const ProgressFn& progress,
                                   const std::function<bool(std::size_t)>& may_pinch) {
    const std::size_t n = mesh.positions.size();
    // Its passes: the incident triangles (counted, made, listed: 0 to 0.5), the fans (to 1).
    const detail::PassProgress counted(progress, 0, 0.1, "mesh"),
        each_vertex(progress, 0.5, 1, "mesh");
    check_adjacency_size(3 * std::uint64_t{mesh.triangles.size()}, "triangle corners");
    // The incident triangles of the vertices looked at (all, or those that may be pinched),
    // by their rank among them.
    // With may_pinch, the vertices looked at are a bit each, a word of 64 of them with the
    // count of those before it: a vertex's rank is that count and the bits below its own.
    // (An array of ranks was 4 bytes a pixel at the mesh's peak, for a few vertices.)
    detail::RankedBits looked;
    std::size_t looked_at = n;
    if (may_pinch) {  // (asked on every thread, a word each; counted in order)
        counted.at(0, 1);
        looked = detail::RankedBits(n);
        auto& words = looked.words();
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, words.size(), std::size_t{1} << 8),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t w = r.begin(); w < r.end(); ++w)
                                  for (std::size_t v = 64 * w; v < std::min(n, 64 * w + 64); ++v)
                                      if (may_pinch(v)) words[w] |= std::uint64_t{1} << (v % 64);
                          });
        looked.count();
        looked_at = looked.members();
    }
    const auto rank = [&](std::int32_t v) -> std::int32_t {
        if (!may_pinch) return v;
        if (!looked.test(std::size_t(v))) return -1;
        return static_cast<std::int32_t>(looked.rank(std::size_t(v)));
    };
    // The corners at vertices looked at, (rank, triangle): with may_pinch (a few vertices of a
    // large grid) gathered by slices of triangles on every thread, in triangle order within
    // each, then counted and listed slice by slice; else (every vertex: a mesh file) counted
    // and listed in two passes over the triangles.
    const std::size_t nt = mesh.triangles.size();
    std::vector<std::vector<std::pair<std::int32_t, std::int32_t>>> corners;
    if (may_pinch)
        corners = gather_by_slices<std::pair<std::int32_t, std::int32_t>>(
            nt, [&](std::size_t t, auto& out) {
                for (auto v : mesh.triangles[t])
                    if (const std::int32_t k = rank(v); k >= 0)
                        out.emplace_back(k, std::int32_t(t));
            });
    report_progress(progress, 0.15, "mesh");
    std::vector<std::uint32_t> offsets(looked_at + 1, 0);
    if (may_pinch) {
        for (const auto& list : corners)
            for (const auto& c : list) ++offsets[std::size_t(c.first) + 1];
    } else {
        for (std::size_t t = 0; t < nt; ++t)
            for (auto v : mesh.triangles[t]) ++offsets[std::size_t(v) + 1];
    }
    for (std::size_t r = 0; r < looked_at; ++r) offsets[r + 1] += offsets[r];
    std::vector<std::int32_t> incident;
    detail::assign_in_slices(incident, offsets.back(), 0,
                             detail::PassProgress(progress, 0.15, 0.3, "mesh"));
    {
        std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
        if (may_pinch) {
            for (auto& list : corners) {
                for (const auto& c : list) incident[fill[std::size_t(c.first)]++] = c.second;
                detail::release(list);
            }
        } else {
            for (std::size_t t = 0; t < nt; ++t)
                for (auto v : mesh.triangles[t]) incident[fill[std::size_t(v)]++] = std::int32_t(t);
        }
    }
    report_progress(progress, 0.5, "mesh");
    std::size_t split = 0;
    std::vector<std::pair<std::int32_t, std::int32_t>> others;  // (other vertex, local index)
    detail::DisjointSets<std::int32_t> fans_of;  // the triangles around v, by local index
    std::vector<std::int32_t> size;
    constexpr std::int32_t kPairwise = 16;
    for (std::size_t v = 0; v < n; ++v) {
        each_vertex.at(v, n);
        const std::int32_t r = rank(std::int32_t(v));
        if (r < 0) continue;
        const std::size_t begin = offsets[std::size_t(r)];
        const auto k =
            static_cast<std::int32_t>(offsets[std::size_t(r) + 1] - begin);  // a fan's size
        if (k < 2) continue;
        fans_of.reset(static_cast<std::size_t>(k));
        auto find = [&](std::int32_t x) { return fans_of.find(x); };
        auto unite = [&](std::int32_t i, std::int32_t j) { fans_of.unite_to_smaller(i, j); };
        // Two triangles at v are in one fan when they share another corner (an edge at v).
        if (k <= kPairwise) {
            // The usual few triangles: compared pair by pair, no sort.
            std::array<std::int32_t, 2 * kPairwise> oc{};
            for (std::int32_t i = 0; i < k; ++i) {
                int j = 0;
                for (auto w : mesh.triangles[incident[begin + i]])
                    if (w != std::int32_t(v) && j < 2) oc[2 * i + j++] = w;
            }
            for (std::int32_t i = 0; i < k; ++i)
                for (std::int32_t j = i + 1; j < k; ++j)
                    if (oc[2 * i] == oc[2 * j] || oc[2 * i] == oc[2 * j + 1] ||
                        oc[2 * i + 1] == oc[2 * j] || oc[2 * i + 1] == oc[2 * j + 1])
                        unite(i, j);
        } else {
            others.clear();
            for (std::int32_t i = 0; i < k; ++i)
                for (auto w : mesh.triangles[incident[begin + i]])
                    if (w != std::int32_t(v)) others.emplace_back(w, i);
            std::sort(others.begin(), others.end());
            for (std::size_t i = 1; i < others.size(); ++i)
                if (others[i].first == others[i - 1].first)
                    unite(others[i].second, others[i - 1].second);
        }
        // Fan sizes by root; roots are the lowest local index of their fan.
        size.assign(k, 0);
        for (std::int32_t i = 0; i < k; ++i) ++size[find(i)];
        std::int32_t keep = -1, fans = 0;
        for (std::int32_t i = 0; i < k; ++i)
            if (size[i] > 0) {
                ++fans;
                if (keep < 0 || size[i] > size[keep]) keep = i;
            }
        if (fans < 2) continue;
        if (split++ == 0 && first_pinched) *first_pinched = std::int32_t(v);
        for (std::int32_t root = 0; root < k; ++root) {
            if (size[root] == 0 || root == keep) continue;
            const auto copy = std::int32_t(mesh.positions.size());
            mesh.positions.push_back(mesh.positions[v]);
            if (!mesh.vertex_pixel.empty()) mesh.vertex_pixel.push_back(mesh.vertex_pixel[v]);
            for (std::int32_t i = 0; i < k; ++i)
                if (find(i) == root)
                    for (auto& w : mesh.triangles[incident[begin + i]])
                        if (w == std::int32_t(v)) w = copy;
        }
    }
    return split;
}

std::size_t remove_unreferenced_vertices(TriangleMesh& mesh, const ProgressFn& progress) {
    // Its passes: the corners (0 to 0.4), the vertices (to 0.6), the corners again (to 1).
    const detail::PassProgress kept(progress, 0.4, 0.6, "mesh"),
        renumbered(progress, 0.6, 1, "mesh");
    const std::size_t nt = mesh.triangles.size(), nv = mesh.positions.size();
    // The corners marked in a bitmap on every thread (an OR, the same in any order), then
    // counted: a whole grid has no vertex to remove, and is left as it is. A vertex's new
    // number is the count of marked vertices before it: the marks before its word (counted
    // once) and in its word. (A number a vertex beside the triangles was 4 bytes a pixel more
    // at the mesh's peak.)
    detail::RankedBits used(nv);
    auto& words = used.words();
    detail::parallel_slices(nt, std::size_t{4096}, progress, 0, 0.4, "mesh",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t i = r.begin(); i < r.end(); ++i)
                                    for (auto v : mesh.triangles[i])
                                        std::atomic_ref<std::uint64_t>(words[std::size_t(v) / 64])
                                            .fetch_or(std::uint64_t{1} << (std::size_t(v) % 64),
                                                      std::memory_order_relaxed);
                            });
    used.count();
    const std::size_t unused = nv - used.members();
    if (unused == 0) {
        report_progress(progress, 1, "mesh");
        return 0;
    }
    const auto marked = [&](std::size_t v) { return used.test(v); };
    const auto remap = [&](std::int32_t v) {
        return static_cast<std::int32_t>(used.rank(std::size_t(v)));
    };
    const bool pixels = !mesh.vertex_pixel.empty();
    std::int32_t next = 0;
    for (std::size_t v = 0; v < nv; ++v) {
        kept.at(v, nv);
        if (!marked(v)) continue;
        mesh.positions[next] = mesh.positions[v];
        if (pixels) mesh.vertex_pixel[next] = mesh.vertex_pixel[v];
        ++next;
    }
    mesh.positions.resize(next);
    if (pixels) mesh.vertex_pixel.resize(next);
    for (std::size_t i = 0; i < nt; ++i) {
        renumbered.at(i, nt);
        for (auto& v : mesh.triangles[i]) v = remap(v);
    }
    // (A pole vertex in no triangle is removed too: it names none then.)
    for (auto& pv : mesh.pole_vertices)
        if (pv >= 0) pv = marked(std::size_t(pv)) ? remap(pv) : -1;
    return unused;
}

}  // namespace terrain
