// The triangle mesh (docs/mesh.md): its memory, its triangles and positions released and made
// again, its positions about an origin, its edge slots and mean vertex area. Its adjacency:
// mesh_adjacency.cpp; its vertex areas: vertex_areas.cpp; its topology: mesh_topology.cpp;
// pinches and unreferenced vertices: vertex_repairs.cpp.
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/release.hpp"
#include "terrain/internal/mesh/grid_triangles.hpp"

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
    return positions_.capacity() * sizeof(positions_[0]) +
           triangles_.capacity() * sizeof(triangles_[0]) + vertex_areas.capacity() * sizeof(float) +
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

void TriangleMesh::drop_geometry() {
    detail::release(positions_);
    detail::release(triangles_);
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
    return !triangles_.empty() && grid_describes_it();
}

bool TriangleMesh::release_triangles() {
    if (triangles_released()) return true;
    if (!triangles_releasable()) return false;
    released_triangles_ = triangles_.size();
    detail::release(triangles_);
    return true;
}

void TriangleMesh::restore_triangles() {
    if (!triangles_released()) return;
    std::vector<std::array<std::int32_t, 3>> made;
    made.reserve(released_triangles_);
    detail::for_each_triangle(*this, [&](std::size_t, const auto& t) { made.push_back(t); });
    if (made.size() != released_triangles_)
        throw Error("mesh", "internal: the triangles made again are not those released");
    triangles_ = std::move(made);
    released_triangles_ = 0;
}

bool TriangleMesh::release_positions() {
    if (positions_released()) return true;
    if (positions_.empty() || !grid_describes_it()) return false;
    released_vertices_ = positions_.size();
    detail::release(positions_);
    return true;
}

void TriangleMesh::set_restored_positions(std::vector<std::array<float, 3>>&& placed) {
    if (!positions_released() || placed.size() != released_vertices_)
        throw Error("mesh", "internal: the positions placed again are not one a vertex");
    positions_ = std::move(placed);
    released_vertices_ = 0;
}

void TriangleMesh::away(const char* what) {
    throw Error("mesh", std::string("internal: the mesh's ") + what +
                            " were read while released (read them through the grid)");
}

void TriangleMesh::for_each_triangle(
    const std::function<void(std::size_t, const Triangle&)>& f) const {
    detail::for_each_triangle(*this, f);
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
    detail::assign_in_slices(mesh.edit_positions(), n, std::array<float, 3>{},
                             detail::PassProgress(progress, 0.3, 0.6, "mesh"));
    detail::parallel_slices(
        n, std::size_t{4096}, progress, 0.6, 1, "mesh",
        [&, &positions = mesh.edit_positions()](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t v = r.begin(); v < r.end(); ++v)
                for (int k = 0; k < 3; ++k)
                    positions[v][k] = static_cast<float>(points[v][k] - mesh.origin[k]);
        });
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

}  // namespace terrain
