// The shape index (docs/field.md): each vertex's fit by the mesh method (the rings window
// four vertices at a time, the ball gathered on the mesh), the dispatch to the grid method
// (shape_index_grid.cpp) and the disk window (shape_index_disk.cpp), and the field made of
// the fits.
#include "terrain/field/shape_index.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>

#include "curvature_fit.hpp"
#include "shape_index_fit.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/pass_progress.hpp"

namespace terrain::field {
namespace detail {

namespace {

// The neighbourhood of v: `rings` rings of mesh edges, or everything within `radius` metres
// (a ball) reachable through vertices within it.
void gather(const TriangleMesh& mesh, std::int32_t v, const ShapeIndexOptions& options,
            Scratch& s) {
    if (!(options.radius > 0))
        return gather_where(
            mesh, v, options.rings, [](std::int32_t) { return true; }, s);
    const auto& centre = mesh.positions()[v];
    const double r2 = options.radius * options.radius;
    gather_where(
        mesh, v, -1,
        [&](std::int32_t w) {
            const Vec3 d = sub(mesh.positions()[w], centre);
            return dot(d, d) <= r2;
        },
        s);
}

}  // namespace

void gather_rings(const TriangleMesh& mesh, std::int32_t v, int rings, SmallVertexSet& visited,
                  std::vector<std::int32_t>& gathered) {
    visited.clear();
    gather_breadth_first(
        mesh, v, rings, [](std::int32_t) { return true; },
        [&](std::int32_t w) { return visited.insert(w); }, gathered);
}

// Where v and each of its neighbours lie in the mesh's uniform ranges, each neighbour is the
// vertex plus its direction's offset (TriangleMesh::neighbors_of), so the second ring's cells
// are told apart by their pixel offset within the 5 x 5 pixels around v (a row of at least 5
// pixels: offsets that differ give vertices that differ).
bool gather_two_rings_on_grid(const TriangleMesh& mesh, std::int32_t v,
                              std::vector<std::int32_t>& out) {
    static constexpr int kDx[8] = {-1, 0, 1, -1, 1, -1, 0, 1}, kDy[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
    const auto uniform = [&](std::int32_t u) {
        for (const auto& r : mesh.uniform_ranges)
            if (u < r[1]) return u >= r[0];
        return false;
    };
    if (mesh.grid_width < 5 || !mesh.grid_adjacency() || !uniform(v)) return false;
    const unsigned bits = mesh.neighbor_directions[std::size_t(v)];
    if (bits == 0) return false;
    const auto cell = [](int dx, int dy) { return 1u << ((dy + 2) * 5 + dx + 2); };
    out.clear();
    out.push_back(v);
    std::uint32_t seen = cell(0, 0);
    std::array<int, 8> first_dir{};  // the direction of each first-ring neighbour
    int first = 0;
    for (unsigned b = bits; b != 0; b &= b - 1) {
        const int d = __builtin_ctz(b);
        const auto u =
            static_cast<std::int32_t>(std::int64_t(v) + mesh.direction_offsets[std::size_t(d)]);
        if (!uniform(u) || mesh.neighbor_directions[std::size_t(u)] == 0) return false;
        seen |= cell(kDx[d], kDy[d]);
        first_dir[std::size_t(first++)] = d;
        out.push_back(u);
    }
    for (int i = 0; i < first; ++i) {
        const int d1 = first_dir[std::size_t(i)];
        const std::int32_t u = out[std::size_t(i + 1)];
        for (unsigned b = mesh.neighbor_directions[std::size_t(u)]; b != 0; b &= b - 1) {
            const int d2 = __builtin_ctz(b);
            const std::uint32_t c = cell(kDx[d1] + kDx[d2], kDy[d1] + kDy[d2]);
            if (seen & c) continue;
            seen |= c;
            out.push_back(static_cast<std::int32_t>(std::int64_t(u) +
                                                    mesh.direction_offsets[std::size_t(d2)]));
        }
    }
    return true;
}

// The mesh path for one vertex: gather its neighbourhood on the mesh and fit. With
// `disk_grid` (the disk window applies) the neighbourhood is the vertex's disk, except at a
// collapsed pole, whose pixel is no place on the ground: it takes the ball.
bool mesh_fit(const TriangleMesh& mesh, std::int32_t v, const Vec3& normal,
              const ShapeIndexOptions& options, const GridLayout* disk_grid, Scratch& s,
              PrincipalCurvatures& k, double& scale) {
    const bool pole = v == mesh.pole_vertices[0] || v == mesh.pole_vertices[1];
    if (disk_grid && !pole)
        return disk_mesh_fit(mesh, *disk_grid, v, normal, options.radius, !options.skip_wide, s, k,
                             scale);
    gather(mesh, v, options, s);
    return fit_curvatures(mesh, v, normal, s.gathered.data() + 1, s.gathered.size() - 1, k, scale);
}

namespace {

// Lane buffers of fit_in_batches: each lane's neighbours; the rings gathered on the mesh.
struct BatchScratch {
    std::array<std::vector<std::int32_t>, kFitLanes> neighbours;
    SmallVertexSet visited;
    std::vector<std::int32_t> gathered;
};

// The rings window's vertices [begin, end) through `body`: each gathered as mesh_fit gathers
// it (off the grid, or on the mesh with a small set of the vertices seen instead of a stamp
// per vertex of the mesh: 4 bytes a vertex a thread less), then fitted kFitLanes at a time
// (the last few one by one). Each vertex gets the bits mesh_fit gives it.
template <class Body>
void fit_in_batches(const TriangleMesh& mesh, const std::vector<Vec3>& normals,
                    const ShapeIndexOptions& options, std::int32_t begin, std::int32_t end,
                    BatchScratch& lanes, Body& body) {
    FitBatch batch;
    std::size_t filled = 0;
    const bool two_rings = options.rings == 2;
    for (std::int32_t v = begin; v < end; ++v) {
        auto& own = lanes.neighbours[filled];
        if (two_rings && gather_two_rings_on_grid(mesh, v, own)) {
            own.erase(own.begin());  // (v itself)
        } else {
            gather_rings(mesh, v, options.rings, lanes.visited, lanes.gathered);
            own.assign(lanes.gathered.begin() + 1, lanes.gathered.end());
        }
        batch.vertex[filled] = v;
        batch.neighbours[filled] = own.data();
        batch.normal[filled] = normals[std::size_t(v)];
        batch.m[filled] = own.size();
        if (++filled < std::size_t(kFitLanes)) continue;
        std::array<PrincipalCurvatures, kFitLanes> k;
        std::array<double, kFitLanes> scale{};
        std::array<bool, kFitLanes> ok{};
        fit_curvatures_batch(mesh, batch, k, scale, ok);
        for (std::size_t l = 0; l < filled; ++l) body(batch.vertex[l], ok[l], k[l], scale[l]);
        filled = 0;
    }
    for (std::size_t l = 0; l < filled; ++l) {
        PrincipalCurvatures k;
        double scale = 0;
        const bool ok = fit_curvatures(mesh, batch.vertex[l], batch.normal[l], batch.neighbours[l],
                                       batch.m[l], k, scale);
        body(batch.vertex[l], ok, k, scale);
    }
}

template <class Body>
void for_each_vertex(const TriangleMesh& mesh, const ShapeIndexOptions& options,
                     const ProgressFn& progress, Body body) {
    if (options.radius <= 0 && options.rings < 1)
        throw Error("field", "--rings must be at least 1");
    if (options.radius < 0 || !std::isfinite(options.radius))
        throw Error("field", "--radius must be a positive number of metres");
    // Normals 0 to 0.05 of the progress (the grid method's, when made by bands, with its
    // tiles), the grid's layout to 0.06, the vertices to 1.
    const bool grid = grid_applies(mesh, options), disk = disk_applies(mesh, options);
    // Most windows reaching past the tables: the disk's would be cut to them, the ball's
    // gathered on the mesh at a cost of its area.
    if ((disk || grid) && !options.skip_wide) check_window_reach(mesh, options.radius, "--radius");
    if (grid) return grid_method_for_each_vertex(mesh, options, progress, body);
    const auto normals = vertex_normals(mesh, scaled_progress(progress, 0, 0.05));
    GridLayout layout;
    if (disk) layout = grid_layout(mesh, options.disk_tile_angle);
    report_progress(progress, 0.06, "shape index");
    const GridLayout* disk_grid = disk ? &layout : nullptr;
    // The rings window fits its vertices kFitLanes at a time (fit_curvatures_batch; a lane
    // with fewer neighbours than the others keeps its sums while they go on).
    const bool batched = !disk && !(options.radius > 0);
    const auto n = static_cast<std::int32_t>(mesh.vertex_count());
    tbb::enumerable_thread_specific<Scratch> scratch;
    tbb::enumerable_thread_specific<BatchScratch> batches;
    const std::int32_t chunk = 1 << 16;
    for (std::int32_t start = 0; start < n; start += chunk) {
        const std::int32_t stop = std::min(n, start + chunk);
        tbb::parallel_for(tbb::blocked_range<std::int32_t>(start, stop, 512), [&](const auto& r) {
            if (batched) {
                fit_in_batches(mesh, normals, options, r.begin(), r.end(), batches.local(), body);
                return;
            }
            Scratch& s = scratch.local();
            for (std::int32_t v = r.begin(); v < r.end(); ++v) {
                if (!row_asked(mesh, options, v)) continue;
                PrincipalCurvatures k;
                double scale = 0;
                const bool ok = mesh_fit(mesh, v, normals[v], options, disk_grid, s, k, scale);
                body(v, ok, k, scale);
            }
        });
        report_progress(progress, 0.06 + 0.94 * double(stop) / n, "shape index");
    }
}

}  // namespace

bool row_asked(const TriangleMesh& mesh, const ShapeIndexOptions& options, std::int32_t v) {
    if (mesh.grid_width <= 0 || mesh.vertex_pixel.size() != mesh.vertex_count()) return true;
    const auto row = std::int64_t(mesh.vertex_pixel[std::size_t(v)]) / mesh.grid_width;
    return row >= options.first_row && row < options.end_row;
}

void for_each_curvature(const TriangleMesh& mesh, const ShapeIndexOptions& options,
                        const ProgressFn& progress, const CurvatureBody& body) {
    for_each_vertex(mesh, options, progress, body);
}

}  // namespace detail

using namespace detail;

double shape_index(double k1, double k2) {
    if (k1 < k2) std::swap(k1, k2);
    if (k1 == 0 && k2 == 0) return 0.0;
    return 2.0 / std::numbers::pi * std::atan2(k1 + k2, k1 - k2);
}

const char* shape_index_method(const TriangleMesh& mesh, const ShapeIndexOptions& options) {
    return grid_applies(mesh, options) ? "grid" : "mesh";
}

const char* shape_index_window(const TriangleMesh& mesh, const ShapeIndexOptions& options) {
    if (!(options.radius > 0)) return "rings";
    return disk_applies(mesh, options) ? "disk" : "ball";
}

std::vector<PrincipalCurvatures> principal_curvatures(const TriangleMesh& mesh,
                                                      const ShapeIndexOptions& options,
                                                      const ProgressFn& progress) {
    std::vector<PrincipalCurvatures> out(mesh.vertex_count());
    for_each_vertex(mesh, options, progress,
                    [&](std::int32_t v, bool ok, const PrincipalCurvatures& k, double scale) {
                        if (ok) out[v] = {k.k1 / scale, k.k2 / scale, k.noise / (scale * scale)};
                    });
    return out;
}

std::vector<float> shape_index_field(const TriangleMesh& mesh, const ShapeIndexOptions& options,
                                     const ProgressFn& progress) {
    if (options.auto_scale) return scale_selected_shape_index(mesh, options, progress).field;
    constexpr float kUnknown = -1.0f;
    std::vector<float> field(mesh.vertex_count(), kUnknown);
    for_each_vertex(mesh, options, progress,
                    [&](std::int32_t v, bool ok, const PrincipalCurvatures& k, double) {
                        if (!ok) return;
                        // Scale-free curvatures: curvedness relative to the neighbourhood size.
                        const double curvedness = std::sqrt(0.5 * (k.k1 * k.k1 + k.k2 * k.k2));
                        const double si =
                            curvedness < options.planar_curvedness ? 0.0 : shape_index(k.k1, k.k2);
                        field[v] = static_cast<float>(50.0 * (si + 1.0));
                    });
    // Vertices whose neighbourhood was too small take the mean of their known neighbours,
    // sweeping until none is left (a component with no known vertex is planar: 50).
    for (bool changed = true; changed;) {
        changed = false;
        std::vector<std::pair<std::int32_t, float>> updates;
        const terrain::detail::PassProgress pass(progress, 1, 1, "shape index");
        for (std::size_t v = 0; v < field.size(); ++v) {
            pass.at(v, field.size());
            if (field[v] != kUnknown) continue;
            double sum = 0;
            int count = 0;
            for (const auto w : mesh.neighbors_of(v))
                if (field[w] != kUnknown) sum += field[w], ++count;
            if (count > 0) updates.emplace_back(std::int32_t(v), float(sum / count));
        }
        for (const auto& [v, value] : updates) field[v] = value;
        changed = !updates.empty();
    }
    for (auto& f : field)
        if (f == kUnknown) f = 50.0f;
    return field;
}

}  // namespace terrain::field