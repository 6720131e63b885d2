// The adjacency of a mesh: sorted neighbour lists from the triangles' edges (finish_mesh),
// or on a DEM mesh the eight directions of the grid with explicit lists for the irregular
// vertices only (finish_grid_mesh); docs/mesh.md.
#include "terrain/mesh/triangle_mesh.hpp"

#include <tbb/blocked_range.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <numeric>
#include <string>
#include <vector>

#include "mesh_lists.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/release.hpp"
#include "terrain/internal/mesh/grid_triangles.hpp"
#include "vertex_areas.hpp"

namespace terrain {

using detail::check_adjacency_size;
using detail::gather_by_slices;
using detail::pack_sorted_lists;
using detail::set_grid_vertex_areas;
using detail::set_vertex_areas;

void finish_mesh(TriangleMesh& mesh, const ProgressFn& progress) {
    const std::size_t n = mesh.positions().size();
    // Its passes: areas (0 to 0.25), the corners' lists (counted, made, filled: to 0.6),
    // sorted (to 0.9), copied at their size (to 1).
    const detail::PassProgress counts(progress, 0.25, 0.35, "mesh"),
        lists(progress, 0.45, 0.6, "mesh");
    const std::size_t nt = mesh.triangles().size();
    mesh.release_adjacency();
    set_vertex_areas(mesh, detail::PassProgress(progress, 0, 0.25, "mesh"));
    report_progress(progress, 0.25, "mesh");

    // CSR adjacency from the triangles' edges, each list sorted and without repeats. Before
    // the repeats go there are two entries per triangle corner (12 per vertex of a grid,
    // past 2^31 at 179 M vertices): 32-bit unsigned offsets, checked.
    check_adjacency_size(6 * std::uint64_t{mesh.triangles().size()}, "triangle corners");
    std::vector<std::uint32_t> offsets(n + 1, 0);
    for (std::size_t i = 0; i < nt; ++i) {
        counts.at(i, nt);
        for (int k = 0; k < 3; ++k) offsets[mesh.triangles()[i][k] + 1] += 2;
    }
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    std::vector<std::int32_t> all;
    detail::assign_in_slices(all, offsets.back(), 0,
                             detail::PassProgress(progress, 0.35, 0.45, "mesh"));
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t i = 0; i < nt; ++i) {
        lists.at(i, nt);
        const auto& t = mesh.triangles()[i];
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

namespace {

// The direction of the pixel dp away on a grid W pixels wide (-1: not one of the 8 around,
// or across the seam, which comes out of order and is left to the explicit lists).
int grid_direction(std::int64_t W, std::int64_t dp) {
    if (dp >= -W - 1 && dp <= -W + 1) return static_cast<int>(dp + W + 1);
    if (dp == -1 || dp == 1) return dp < 0 ? 3 : 4;
    if (dp >= W - 1 && dp <= W + 1) return static_cast<int>(dp - W + 6);
    return -1;
}

// Every edge a -> b of a triangle sets a's bit towards b's pixel in `bits`, or marks a in
// `irregular` when b is not the vertex of a pixel around a's (a pole, a pinch's copy);
// progress 0.3 to 0.6.
void mark_grid_directions(const TriangleMesh& mesh, bool by_rows, const ProgressFn& progress,
                          std::vector<std::uint8_t>& bits, std::vector<std::uint8_t>& irregular) {
    const std::int64_t W = mesh.grid_width;
    const std::size_t n = mesh.positions().size();
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
                const int d = grid_direction(W, pb - pa);
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
        detail::parallel_slices(
            mesh.triangle_count(), std::size_t{4096}, progress, 0.35, 0.6, "mesh",
            [&, &triangles = mesh.triangles()](const tbb::blocked_range<std::size_t>& r) {
                for (std::size_t i = r.begin(); i < r.end(); ++i) mark(triangles[i]);
            });
}

// Marks irregular the vertices whose neighbours, read off the grid in the directions' order,
// do not come in increasing order (across the seam, or next to a pinch's copy); progress 0.6
// to 0.8. Returns the sum of the regular vertices' degrees.
std::uint64_t mark_unordered_vertices(const TriangleMesh& mesh, const ProgressFn& progress,
                                      std::vector<std::uint8_t>& irregular) {
    std::atomic<std::uint64_t> regular_degrees{0};
    detail::parallel_slices(
        mesh.positions().size(), std::size_t{4096}, progress, 0.6, 0.8, "mesh",
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
    return regular_degrees.load();
}

// The irregular vertices (their directions cleared) and their neighbour lists, from their
// triangles, sorted and without repeats. Returns the lists' length.
std::size_t set_irregular_lists(TriangleMesh& mesh, bool by_rows, const ProgressFn& progress,
                                std::vector<std::uint8_t>& irregular) {
    const std::size_t n = mesh.positions().size();
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
    auto corners = by_rows ? gather_by_slices<std::array<std::int32_t, 3>>(
                                 std::size_t(mesh.grid_height - 1),
                                 [&](std::size_t row, auto& out) {
                                     detail::for_each_row_triangle(
                                         mesh, int(row), [&](const auto& t) { gather(t, out); });
                                 })
                           : gather_by_slices<std::array<std::int32_t, 3>>(
                                 mesh.triangle_count(), [&](std::size_t i, auto& out) {
                                     gather(mesh.triangles()[i], out);
                                 });
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
    return write;
}

}  // namespace

void finish_grid_mesh(TriangleMesh& mesh, const ProgressFn& progress) {
    const std::int64_t W = mesh.grid_width;
    const std::size_t n = mesh.positions().size();
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
    std::vector<std::uint8_t> bits, irregular;
    mark_grid_directions(mesh, by_rows, progress, bits, irregular);
    mesh.neighbor_directions = std::move(bits);
    const std::uint64_t regular_degrees = mark_unordered_vertices(mesh, progress, irregular);
    const std::size_t write = set_irregular_lists(mesh, by_rows, progress, irregular);
    mesh.grid_edges = static_cast<std::size_t>((regular_degrees + write) / 2);
}

}  // namespace terrain
