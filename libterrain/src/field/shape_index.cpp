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
#include <span>

#include "../core/pass_progress.hpp"
#include "../mesh/grid_triangles.hpp"
#include "shape_index_fit.hpp"
#include "terrain/core/error.hpp"

namespace terrain::field {
namespace detail {

namespace {

// Adds triangle t's area-weighted normal (counter-clockwise seen from outside/above) to its
// corners v that take(v) takes, at normals[v - first].
template <class Take>
void add_normal(const TriangleMesh& mesh, const std::array<std::int32_t, 3>& t, std::size_t first,
                std::vector<Vec3>& normals, const Take& take) {
    const auto& p = mesh.positions;
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

namespace {

// The neighbourhood of v: `rings` rings of mesh edges, or everything within `radius` metres
// (a ball) reachable through vertices within it.
void gather(const TriangleMesh& mesh, std::int32_t v, const ShapeIndexOptions& options,
            Scratch& s) {
    if (!(options.radius > 0))
        return gather_where(
            mesh, v, options.rings, [](std::int32_t) { return true; }, s);
    const auto& centre = mesh.positions[v];
    const double r2 = options.radius * options.radius;
    gather_where(
        mesh, v, -1,
        [&](std::int32_t w) {
            const Vec3 d = sub(mesh.positions[w], centre);
            return dot(d, d) <= r2;
        },
        s);
}

}  // namespace

GridLayout grid_layout(const TriangleMesh& mesh, double tile_angle) {
    GridLayout g;
    g.width = mesh.grid_width, g.height = mesh.grid_height;
    g.seam = mesh.seam_closed;
    const std::size_t pixels = std::size_t(g.width) * std::size_t(g.height);
    if (mesh.pixel_vertex.size() == pixels) {
        g.pixel_vertex = mesh.pixel_vertex.data();
    } else {  // the first copy of a split pinch owns its pixel, as in the mesh's map
        g.own.assign(pixels, -1);
        for (std::size_t v = mesh.vertex_pixel.size(); v-- > 0;)
            g.own[std::size_t(mesh.vertex_pixel[v])] = std::int32_t(v);
        g.pixel_vertex = g.own.data();
    }
    // A collapsed pole row is one vertex: it takes the mesh path.
    g.pole_rows = mesh.pole_rows;
    // On a body, the disk window's tiles are made smaller where 64 pixels span more than
    // kMaxDiskTileAngle: from the longest distance between neighbouring pixels and the
    // largest distance from the body's centre among about 64 x 64 pixels spread over the grid.
    if (mesh.frame == MeshFrame::body) {
        double spacing = 0, radius = 0;
        const int row_step = std::max(1, g.height / 64), col_step = std::max(1, g.width / 64);
        for (int r = 0; r + 1 < g.height; r += row_step)
            for (int c = 0; c + 1 < g.width; c += col_step) {
                const auto v = g.vertex_at(c, r);
                if (v < 0) continue;
                const auto& p = mesh.positions[std::size_t(v)];
                const Vec3 q{mesh.origin[0] + p[0], mesh.origin[1] + p[1], mesh.origin[2] + p[2]};
                radius = std::max(radius, std::sqrt(dot(q, q)));
                for (const auto w : {g.vertex_at(c + 1, r), g.vertex_at(c, r + 1)})
                    if (w >= 0) {
                        const Vec3 d = sub(mesh.positions[std::size_t(w)], p);
                        spacing = std::max(spacing, std::sqrt(dot(d, d)));
                    }
            }
        if (spacing > 0) g.disk_tile = int(std::clamp(tile_angle * radius / spacing, 8.0, 64.0));
    }
    return g;
}

namespace {

bool dem_mesh(const TriangleMesh& mesh) {
    return mesh.grid_width > 0 && mesh.grid_height > 0 &&
           mesh.vertex_pixel.size() == mesh.vertex_count();
}

}  // namespace

bool disk_applies(const TriangleMesh& mesh, const ShapeIndexOptions& options) {
    return options.radius > 0 && options.window == ShapeIndexWindow::disk && dem_mesh(mesh);
}

namespace {

// Solves the symmetric positive system A x = b (n <= 5) by Cholesky; false if singular.
template <int N>
bool solve_spd(std::array<std::array<double, N>, N>& a, std::array<double, N>& b) {
    double trace = 0;
    for (int i = 0; i < N; ++i) trace += a[i][i];
    const double eps = 1e-12 * (trace > 0 ? trace : 1.0);
    for (int j = 0; j < N; ++j) {
        double d = a[j][j];
        for (int k = 0; k < j; ++k) d -= a[j][k] * a[j][k];
        if (d <= eps) return false;
        a[j][j] = std::sqrt(d);
        for (int i = j + 1; i < N; ++i) {
            double s = a[i][j];
            for (int k = 0; k < j; ++k) s -= a[i][k] * a[j][k];
            a[i][j] = s / a[j][j];
        }
    }
    for (int i = 0; i < N; ++i) {
        double s = b[i];
        for (int k = 0; k < i; ++k) s -= a[i][k] * b[k];
        b[i] = s / a[i][i];
    }
    for (int i = N - 1; i >= 0; --i) {
        double s = b[i];
        for (int k = i + 1; k < N; ++k) s -= a[k][i] * b[k];
        b[i] = s / a[i][i];
    }
    return true;
}

// Row i of the inverse of the matrix whose Cholesky factor solve_spd left in `l`, at i:
// |L^-1 e_i|^2.
template <int N>
double inverse_diagonal(const std::array<std::array<double, N>, N>& l, int i) {
    std::array<double, N> y{};
    double sum = 0;
    for (int r = i; r < N; ++r) {
        double s = r == i ? 1.0 : 0.0;
        for (int k = i; k < r; ++k) s -= l[r][k] * y[k];
        y[r] = s / l[r][r];
        sum += y[r] * y[r];
    }
    return sum;
}

// The noise factor of PrincipalCurvatures for a fit h = a u^2 + b uv + c v^2 (+ ...) whose
// normal matrix has the Cholesky factor `l`: the curvedness is sqrt(2 a^2 + b^2 + 2 c^2)
// (slopes neglected), and white noise of unit variance gives var(a) = (A^-1)_00, ...
template <int N>
double curvedness_noise(const std::array<std::array<double, N>, N>& l) {
    return std::sqrt(2 * inverse_diagonal<N>(l, 0) + inverse_diagonal<N>(l, 1) +
                     2 * inverse_diagonal<N>(l, 2));
}

}  // namespace

// Solves the fit with coordinates divided by `scale` (so that it is scale-free; dividing only
// rescales the equations) and returns the principal curvatures in units of 1/scale; false
// when the neighbourhood is too small.
bool solve_curvatures(NormalEquations e, PrincipalCurvatures& out) {
    auto& ata = e.ata;
    auto& atb = e.atb;
    const std::size_t m = e.m;
    if (m < 3) return false;
    const double scale = e.scale;
    if (!(scale > 0)) return false;
    const double inv = 1.0 / scale;
    const double unit[5] = {inv * inv, inv * inv, inv * inv, inv, inv};
    for (int i = 0; i < 5; ++i) {
        for (int j = 0; j <= i; ++j) ata[i][j] *= unit[i] * unit[j];
        atb[i] *= unit[i] * inv;
    }
    double a = 0, b = 0, c = 0, du = 0, dv = 0;
    bool full = false;  // with the linear terms, which absorb an imprecise normal
    if (m >= 5) {
        auto A = ata;
        auto B = atb;
        if (solve_spd<5>(A, B)) {
            a = B[0], b = B[1], c = B[2], du = B[3], dv = B[4];
            full = true;
            out.noise = curvedness_noise<5>(A);
        }
    }
    if (!full) {
        std::array<std::array<double, 3>, 3> A{};
        std::array<double, 3> B{atb[0], atb[1], atb[2]};
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j <= i; ++j) A[i][j] = ata[i][j];
        if (!solve_spd<3>(A, B)) return false;
        a = B[0], b = B[1], c = B[2];
        out.noise = curvedness_noise<3>(A);
    }
    // Fundamental forms of the graph surface at the origin (normal pointing up).
    const double E = 1 + du * du, F = du * dv, G = 1 + dv * dv;
    const double W = std::sqrt(1 + du * du + dv * dv);
    const double L = 2 * a / W, M = b / W, N = 2 * c / W;
    const double det = E * G - F * F;
    const double K = (L * N - M * M) / det;
    // The surface bends away from the normal (a cap) when h decreases: convex positive.
    const double H = -(E * N - 2 * F * M + G * L) / (2 * det);
    const double root = std::sqrt(std::max(0.0, H * H - K));
    out.k1 = H + root;
    out.k2 = H - root;
    return true;
}

// The tangent frame (t1, t2) of a vertex normal.
std::array<Vec3, 2> tangent_frame(const Vec3& normal) {
    const Vec3 axis = std::abs(normal[0]) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 t1 = normalized(cross(normal, axis));
    return {t1, cross(normal, t1)};
}

// Fits h = a u^2 + b uv + c v^2 (+ d u + e v) to the neighbourhood in the tangent frame of
// `normal`, coordinates divided by their mean distance so the fit is scale-free. Returns
// false when the neighbourhood is too small. Curvatures come back in units of 1/scale.
bool fit_curvatures(const TriangleMesh& mesh, std::int32_t v, const Vec3& normal,
                    const std::int32_t* neighbour_ids, std::size_t m, PrincipalCurvatures& out,
                    double& scale) {
    const std::span<const std::int32_t> neighbours(neighbour_ids, m);
    if (m < 3) return false;
    const auto [t1, t2] = tangent_frame(normal);
    // One pass: the normal equations of the raw tangent coordinates and their mean distance.
    const auto& centre = mesh.positions[v];
    NormalEquations e;
    e.m = m;
    for (auto w : neighbours) {
        const Vec3 d = sub(mesh.positions[w], centre);
        const double u = dot(d, t1), s = dot(d, t2), h = dot(d, normal);
        e.scale += std::sqrt(u * u + s * s + h * h);
        const double row[5] = {u * u, u * s, s * s, u, s};
        for (int i = 0; i < 5; ++i) {
            for (int j = 0; j <= i; ++j) e.ata[i][j] += row[i] * row[j];
            e.atb[i] += row[i] * h;
        }
    }
    e.scale /= double(m);
    scale = e.scale;
    return solve_curvatures(e, out);
}

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

namespace {

using Lanes = double __attribute__((vector_size(kFitLanes * sizeof(double))));
using LaneMask = std::int64_t __attribute__((vector_size(kFitLanes * sizeof(double))));

// Each lane's square root, in place (by reference: no vector crosses a call by value, whose
// ABI the two builds of fit_curvatures_batch would disagree on).
[[gnu::always_inline]] inline void sqrt_lanes(Lanes& x) {
    for (int l = 0; l < kFitLanes; ++l) x[l] = std::sqrt(x[l]);
}

}  // namespace

// Each step below is fit_curvatures's and solve_curvatures's (5-term fit) on vectors whose
// lane l holds vertex l's numbers. Built for AVX2 and for the baseline, chosen at load time;
// neither contracts a product and a sum into one rounding (no FMA is enabled).
__attribute__((target_clones("avx2", "default"))) void fit_curvatures_batch(
    const TriangleMesh& mesh, const FitBatch& batch,
    std::array<PrincipalCurvatures, kFitLanes>& out, std::array<double, kFitLanes>& scale,
    std::array<bool, kFitLanes>& ok) {
    std::array<bool, kFitLanes> lane_done{};
    const std::size_t m = *std::max_element(batch.m.begin(), batch.m.end());
    if (*std::min_element(batch.m.begin(), batch.m.end()) >= 5) {
        Lanes count = {};
        for (int l = 0; l < kFitLanes; ++l) count[l] = double(batch.m[std::size_t(l)]);
        Lanes t1[3] = {}, t2[3] = {}, n[3] = {}, c[3] = {};
        for (int l = 0; l < kFitLanes; ++l) {
            const auto frame = tangent_frame(batch.normal[std::size_t(l)]);
            const auto& centre = mesh.positions[std::size_t(batch.vertex[std::size_t(l)])];
            for (int i = 0; i < 3; ++i) {
                t1[i][l] = frame[0][std::size_t(i)];
                t2[i][l] = frame[1][std::size_t(i)];
                n[i][l] = batch.normal[std::size_t(l)][std::size_t(i)];
                c[i][l] = centre[std::size_t(i)];
            }
        }
        Lanes ata[5][5] = {}, atb[5] = {}, sum_scale = {};
        for (std::size_t j = 0; j < m; ++j) {
            Lanes d[3] = {};
            LaneMask in = {};  // the lanes with a j-th neighbour; the others read their centre
            for (int l = 0; l < kFitLanes; ++l) {
                const bool has = j < batch.m[std::size_t(l)];
                in[l] = has ? -1 : 0;
                const auto w =
                    has ? batch.neighbours[std::size_t(l)][j] : batch.vertex[std::size_t(l)];
                const auto& q = mesh.positions[std::size_t(w)];
                for (int i = 0; i < 3; ++i) d[i][l] = double(q[std::size_t(i)]);
            }
            for (int i = 0; i < 3; ++i) d[i] = d[i] - c[i];
            const Lanes u = d[0] * t1[0] + d[1] * t1[1] + d[2] * t1[2];
            const Lanes sv = d[0] * t2[0] + d[1] * t2[1] + d[2] * t2[2];
            const Lanes h = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
            Lanes dist = u * u + sv * sv + h * h;
            sqrt_lanes(dist);
            sum_scale = in ? sum_scale + dist : sum_scale;
            const Lanes row[5] = {u * u, u * sv, sv * sv, u, sv};
            for (int i = 0; i < 5; ++i) {
                for (int k = 0; k <= i; ++k)
                    ata[i][k] = in ? ata[i][k] + row[i] * row[k] : ata[i][k];
                atb[i] = in ? atb[i] + row[i] * h : atb[i];
            }
        }
        sum_scale /= count;
        // solve_curvatures: the scaled equations, Cholesky, the fundamental forms.
        const Lanes inv = 1.0 / sum_scale;
        const Lanes unit[5] = {inv * inv, inv * inv, inv * inv, inv, inv};
        Lanes A[5][5], B[5];
        for (int i = 0; i < 5; ++i) {
            for (int k = 0; k <= i; ++k) A[i][k] = ata[i][k] * (unit[i] * unit[k]);
            B[i] = atb[i] * (unit[i] * inv);
        }
        LaneMask failed = !(sum_scale > 0.0);
        Lanes trace = {};
        for (int i = 0; i < 5; ++i) trace += A[i][i];
        const Lanes eps = 1e-12 * (trace > 0.0 ? trace : Lanes{} + 1.0);
        for (int j = 0; j < 5; ++j) {
            Lanes dj = A[j][j];
            for (int k = 0; k < j; ++k) dj -= A[j][k] * A[j][k];
            failed |= dj <= eps;
            sqrt_lanes(dj);
            A[j][j] = dj;
            for (int i = j + 1; i < 5; ++i) {
                Lanes sum = A[i][j];
                for (int k = 0; k < j; ++k) sum -= A[i][k] * A[j][k];
                A[i][j] = sum / A[j][j];
            }
        }
        for (int i = 0; i < 5; ++i) {
            Lanes sum = B[i];
            for (int k = 0; k < i; ++k) sum -= A[i][k] * B[k];
            B[i] = sum / A[i][i];
        }
        for (int i = 4; i >= 0; --i) {
            Lanes sum = B[i];
            for (int k = i + 1; k < 5; ++k) sum -= A[k][i] * B[k];
            B[i] = sum / A[i][i];
        }
        const Lanes a = B[0], b = B[1], cc = B[2], du = B[3], dv = B[4];
        const Lanes E = 1.0 + du * du, F = du * dv, G = 1.0 + dv * dv;
        Lanes W = 1.0 + du * du + dv * dv;
        sqrt_lanes(W);
        const Lanes L = 2.0 * a / W, M = b / W, N = 2.0 * cc / W;
        const Lanes det = E * G - F * F;
        const Lanes K = (L * N - M * M) / det;
        const Lanes H = -(E * N - 2.0 * F * M + G * L) / (2.0 * det);
        Lanes root = H * H - K;
        for (int l = 0; l < kFitLanes; ++l) root[l] = std::max(0.0, root[l]);
        sqrt_lanes(root);
        const Lanes k1 = H + root, k2 = H - root;
        for (int l = 0; l < kFitLanes; ++l) {
            if (failed[l]) continue;
            out[std::size_t(l)] = {k1[l], k2[l]};
            scale[std::size_t(l)] = sum_scale[l];
            ok[std::size_t(l)] = true;
            lane_done[std::size_t(l)] = true;
        }
    }
    for (int l = 0; l < kFitLanes; ++l)
        if (!lane_done[std::size_t(l)])
            ok[std::size_t(l)] =
                fit_curvatures(mesh, batch.vertex[std::size_t(l)], batch.normal[std::size_t(l)],
                               batch.neighbours[std::size_t(l)], batch.m[std::size_t(l)],
                               out[std::size_t(l)], scale[std::size_t(l)]);
}

// The mesh path for one vertex: gather its neighbourhood on the mesh and fit. With
// `disk_grid` (the disk window applies) the neighbourhood is the vertex's disk, except at a
// collapsed pole, whose pixel is no place on the ground: it takes the ball.
bool mesh_fit(const TriangleMesh& mesh, std::int32_t v, const Vec3& normal,
              const ShapeIndexOptions& options, const GridLayout* disk_grid, Scratch& s,
              PrincipalCurvatures& k, double& scale) {
    const bool pole = v == mesh.pole_vertices[0] || v == mesh.pole_vertices[1];
    if (disk_grid && !pole)
        return disk_mesh_fit(mesh, *disk_grid, v, normal, options.radius, s, k, scale);
    gather(mesh, v, options, s);
    return fit_curvatures(mesh, v, normal, s.gathered.data() + 1, s.gathered.size() - 1, k, scale);
}

namespace {

// ---------------------------------------------------------------------------------------------
// The grid path (DEM meshes with a metric radius). The fit above needs, per vertex, sums over
// its neighbours of products of their tangent coordinates u, s, h up to degree 4; each is a
// fixed combination of the moments sum d^a of the 3-D offsets d = p_w - p_v over the 35
// monomials of degree <= 4 in (x, y, z). Those moments are taken about a reference point per
// tile of pixels from per-row prefix sums, so that a window row costs two look-ups whatever
// its length, then moved to the vertex (a Taylor shift) and turned into its tangent frame.
// The window is the same ball as the mesh path's, found row by row: each row's span of pixels
// within the radius is the previous pixel's span with its ends moved, so finding it costs
// O(1) per row on average.

constexpr int kMoments = 35;
constexpr int kDegreeStart[6] = {0, 1, 4, 10, 20, 35};

struct Exponents {
    int x = 0, y = 0, z = 0;
};

// The monomials by degree, then by decreasing x, then decreasing y.
constexpr std::array<Exponents, kMoments> kExponents = [] {
    std::array<Exponents, kMoments> e{};
    int k = 0;
    for (int degree = 0; degree <= 4; ++degree)
        for (int x = degree; x >= 0; --x)
            for (int y = degree - x; y >= 0; --y) e[std::size_t(k++)] = {x, y, degree - x - y};
    return e;
}();

constexpr int moment_index(int x, int y, int z) {
    for (int k = 0; k < kMoments; ++k)
        if (kExponents[std::size_t(k)].x == x && kExponents[std::size_t(k)].y == y &&
            kExponents[std::size_t(k)].z == z)
            return k;
    return -1;
}

// The Taylor shift of the 35 moments along x, y and z (ShiftStep), 3 x 35 steps.
constexpr int kShiftSteps = 105;
constexpr std::array<ShiftStep, kShiftSteps> kShift = [] {
    std::array<ShiftStep, kShiftSteps> steps{};
    int k = 0;
    for (int axis = 0; axis < 3; ++axis)
        for (int o1 = 0; o1 <= 4; ++o1)
            for (int o2 = 0; o1 + o2 <= 4; ++o2) {
                const int n = 4 - o1 - o2;
                const auto at = [&](int e) {
                    return axis == 0   ? moment_index(e, o1, o2)
                           : axis == 1 ? moment_index(o1, e, o2)
                                       : moment_index(o1, o2, e);
                };
                for (int j = 1; j <= n; ++j)
                    for (int e = n; e >= j; --e)
                        steps[std::size_t(k++)] = {std::uint8_t(axis), std::uint8_t(at(e)),
                                                   std::uint8_t(at(e - 1))};
            }
    return steps;
}();

// Products of homogeneous polynomials of degrees P and Q: for each pair of their local
// indices (row-major), the local index of the product's monomial in degree P + Q.
template <int P, int Q>
constexpr auto kProduct = [] {
    constexpr int np = kDegreeStart[P + 1] - kDegreeStart[P];
    constexpr int nq = kDegreeStart[Q + 1] - kDegreeStart[Q];
    std::array<std::uint8_t, std::size_t(np * nq)> t{};
    for (int i = 0; i < np; ++i)
        for (int j = 0; j < nq; ++j) {
            const auto a = kExponents[std::size_t(kDegreeStart[P] + i)];
            const auto b = kExponents[std::size_t(kDegreeStart[Q] + j)];
            t[std::size_t(i * nq + j)] =
                std::uint8_t(moment_index(a.x + b.x, a.y + b.y, a.z + b.z) - kDegreeStart[P + Q]);
        }
    return t;
}();

// The 35 monomials of e.
void monomials(const Vec3& e, double* out) {
    double px[5] = {1, e[0], e[0] * e[0], 0, 0}, py[5] = {1, e[1], e[1] * e[1], 0, 0},
           pz[5] = {1, e[2], e[2] * e[2], 0, 0};
    px[3] = px[2] * e[0], px[4] = px[2] * px[2];
    py[3] = py[2] * e[1], py[4] = py[2] * py[2];
    pz[3] = pz[2] * e[2], pz[4] = pz[2] * pz[2];
#pragma GCC unroll 35
    for (int k = 0; k < kMoments; ++k) {
        const auto a = kExponents[std::size_t(k)];
        out[k] = px[a.x] * py[a.y] * pz[a.z];
    }
}

// A homogeneous polynomial of degree D in (x, y, z), coefficients in moment order.
template <int D>
struct Poly {
    std::array<double, kDegreeStart[D + 1] - kDegreeStart[D]> c{};
};

template <int P, int Q>
Poly<P + Q> multiply(const Poly<P>& p, const Poly<Q>& q) {
    constexpr auto& target = kProduct<P, Q>;
    Poly<P + Q> r;
    std::size_t k = 0;
#pragma GCC unroll 6
    for (std::size_t i = 0; i < p.c.size(); ++i) {
#pragma GCC unroll 15
        for (std::size_t j = 0; j < q.c.size(); ++j) r.c[target[k++]] += p.c[i] * q.c[j];
    }
    return r;
}

template <int D>
double contract(const Poly<D>& p, const double* moments) {
    double s = 0;
#pragma GCC unroll 15
    for (std::size_t i = 0; i < p.c.size(); ++i) s += p.c[i] * moments[kDegreeStart[D] + int(i)];
    return s;
}

// The normal equations of the fit from the moments of the offsets (about the vertex) in the
// tangent frame (t1, t2, n).
NormalEquations equations_from_moments(const double* m, const Vec3& normal) {
    const auto [t1, t2] = tangent_frame(normal);
    const Poly<1> U{{t1[0], t1[1], t1[2]}}, S{{t2[0], t2[1], t2[2]}},
        N{{normal[0], normal[1], normal[2]}};
    const auto UU = multiply(U, U), US = multiply(U, S), SS = multiply(S, S), UN = multiply(U, N),
               SN = multiply(S, N);
    const double u2 = contract(UU, m), us = contract(US, m), s2 = contract(SS, m);
    const double u3 = contract(multiply(UU, U), m), u2s = contract(multiply(UU, S), m),
                 us2 = contract(multiply(SS, U), m), s3 = contract(multiply(SS, S), m);
    const double u4 = contract(multiply(UU, UU), m), u3s = contract(multiply(UU, US), m),
                 u2s2 = contract(multiply(UU, SS), m), us3 = contract(multiply(US, SS), m),
                 s4 = contract(multiply(SS, SS), m);
    NormalEquations e;
    auto& a = e.ata;
    a[0][0] = u4;
    a[1][0] = u3s, a[1][1] = u2s2;
    a[2][0] = u2s2, a[2][1] = us3, a[2][2] = s4;
    a[3][0] = u3, a[3][1] = u2s, a[3][2] = us2, a[3][3] = u2;
    a[4][0] = u2s, a[4][1] = us2, a[4][2] = s3, a[4][3] = us, a[4][4] = s2;
    e.atb = {contract(multiply(UU, N), m), contract(multiply(US, N), m),
             contract(multiply(SS, N), m), contract(UN, m), contract(SN, m)};
    const double count = m[0] - 1;  // the vertex itself is in its window, at d = 0
    e.m = count > 0 ? std::size_t(std::llround(count)) : 0;
    // The mean neighbour distance, which the fit only uses to make itself scale-free and to
    // measure curvedness: the root mean square distance times 2 sqrt(2) / 3, their ratio on a
    // uniformly filled disk.
    const double sum2 = m[4] + m[7] + m[9];  // x^2 + y^2 + z^2
    e.scale =
        count > 0 ? std::sqrt(std::max(0.0, sum2) / count) * (2 * std::numbers::sqrt2 / 3) : 0.0;
    return e;
}

// Moves moments about the reference to moments about the vertex at `centre` (sum (e - t)^a
// from sum e^a, axis by axis), fits and hands the result to `body`.
void fit_from_moments(double* moments, const Vec3& centre, const Vec3& ref, const Vec3& normal,
                      std::int32_t v, const VertexFn& body) {
    const Vec3 t{centre[0] - ref[0], centre[1] - ref[1], centre[2] - ref[2]};
    apply_shift(kShift, t.data(), moments);
    PrincipalCurvatures k;
    const auto equations = equations_from_moments(moments, normal);
    const bool fitted = solve_curvatures(equations, k);
    body(v, fitted, k, equations.scale);
}

// The vertices of one tile of output pixels [c0, c0 + kTile) x [r0, r0 + kTile).
void grid_tile(const TriangleMesh& mesh, const GridLayout& g, const Normals& normals,
               const ShapeIndexOptions& options, int r0, int c0, GridScratch& s,
               std::size_t& mesh_fallbacks, const VertexFn& body) {
    const int W = g.width, H = g.height;
    const int r1 = std::min(H, r0 + kTile), c1 = std::min(W, c0 + kTile);
    const auto fallback = [&](std::int32_t v) {
        tile_fallback(mesh, v, normals[std::size_t(v)], options, nullptr, s, mesh_fallbacks, body);
    };
    // How far (in pixels) the ball can reach: from the short end of the tile's distances
    // between neighbouring pixels, with a margin; a window reaching the margin takes the
    // mesh path.
    const auto reach = [&](int dc, int dr) {
        s.spacing.clear();
        for (int row = r0; row + dr < r1; ++row)
            for (int col = c0; col + dc < c1; ++col) {
                const auto a = g.vertex_at(col, row), b = g.vertex_at(col + dc, row + dr);
                if (a < 0 || b < 0) continue;
                const Vec3 d = sub(mesh.positions[std::size_t(a)], mesh.positions[std::size_t(b)]);
                s.spacing.push_back(std::sqrt(dot(d, d)));
            }
        if (s.spacing.empty()) return kMaxReach + 1;
        const auto tenth = s.spacing.begin() + std::ptrdiff_t(s.spacing.size() / 10);
        std::nth_element(s.spacing.begin(), tenth, s.spacing.end());
        if (!(*tenth > 0)) return kMaxReach + 1;
        const double r = 1.25 * options.radius / *tenth + 2;
        return r > kMaxReach ? kMaxReach + 1 : int(std::ceil(r));
    };
    const int mx = reach(1, 0), my = reach(0, 1);
    Region region;
    const auto status =
        region_sums<kMoments>(mesh, g, r0, r1, c0, c1, mx, my, true, s, region, monomials);
    if (status == RegionStatus::empty) return;
    if (status == RegionStatus::mesh_path)
        return g.for_each_vertex(r0, r1, c0, c1, [&](std::int32_t v, int, int) { fallback(v); });
    const int rr0 = region.rr0, cc0 = region.cc0, rows = region.rows, cols = region.cols;
    const Vec3 ref = region.ref;
    const double r2 = options.radius * options.radius;
    const int offsets = 2 * my + 1;
    s.lo.assign(std::size_t(offsets), 0);
    s.hi.assign(std::size_t(offsets), -1);
    for (int row = r0; row < r1; ++row) {
        bool warm = false;  // the spans hold the previous pixel's window
        const int lr = row - rr0;
        for (int col = c0; col < c1; ++col) {
            const auto v = g.vertex_at(col, row);
            if (v < 0) {
                warm = false;
                continue;
            }
            const int lc = col - cc0;
            const Vec3 centre = s.position[std::size_t(lr) * std::size_t(cols) + std::size_t(lc)];
            // Within the ball, as the mesh path tests it.
            // (A pixel without a vertex has a NaN position: never inside.)
            const auto inside = [&](int r, int c) {
                const Vec3& p = s.position[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
                const Vec3 d{p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]};
                return dot(d, d) <= r2;
            };
            // The next pixel of the row within the ball beyond `from` in direction `step`,
            // stepping over pixels without a vertex, at most mx columns from the centre; -1.
            const auto next_inside = [&](int r, int from, int step) {
                for (int c = from + step; c >= 0 && c < cols && std::abs(c - lc) <= mx; c += step) {
                    if (inside(r, c)) return c;
                    const Vec3& p = s.position[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
                    if (!std::isnan(p[0])) return -1;
                }
                return -1;
            };
            bool ok = true;
            for (int dir = 1; dir >= -1 && ok; dir -= 2) {
                int guess = lc;
                for (int k = dir > 0 ? 0 : 1; k <= my; ++k) {
                    const int dy = dir * k, r = lr + dy;
                    int& lo = s.lo[std::size_t(dy + my)];
                    int& hi = s.hi[std::size_t(dy + my)];
                    if (r < 0 || r >= rows) {
                        lo = 0, hi = -1;
                        continue;
                    }
                    if (warm && lo <= hi) {
                        if (inside(r, hi))
                            for (int c; (c = next_inside(r, hi, 1)) >= 0;) hi = c;
                        else
                            while (hi >= lo && !inside(r, hi)) --hi;
                        if (hi >= lo) {
                            if (inside(r, lo))
                                for (int c; (c = next_inside(r, lo, -1)) >= 0;) lo = c;
                            else
                                while (lo <= hi && !inside(r, lo)) ++lo;
                        }
                    } else {
                        lo = 0, hi = -1;
                    }
                    if (lo > hi) {
                        // Search next to where the row nearer the centre had its middle.
                        for (int t : {0, -1, 1, -2, 2}) {
                            const int c = guess + t;
                            if (c >= 0 && c < cols && inside(r, c)) {
                                lo = hi = c;
                                for (int n; (n = next_inside(r, hi, 1)) >= 0;) hi = n;
                                for (int n; (n = next_inside(r, lo, -1)) >= 0;) lo = n;
                                break;
                            }
                        }
                    }
                    if (lo > hi) {  // the ball ends here: the rows beyond are empty too
                        for (int j = k + 1; j <= my; ++j) {
                            s.lo[std::size_t(dir * j + my)] = 0;
                            s.hi[std::size_t(dir * j + my)] = -1;
                        }
                        break;
                    }
                    guess = (lo + hi) / 2;
                    // At the region's margin the ball may go on beyond it.
                    const bool edge_left = lc - lo >= mx && (g.seam || cc0 + lo > 0);
                    const bool edge_right = hi - lc >= mx && (g.seam || cc0 + hi < W - 1);
                    const bool edge_row = k == my && (dir > 0 ? rr0 + r < H - 1 : rr0 + r > 0);
                    if (edge_left || edge_right || edge_row) {
                        ok = false;
                        break;
                    }
                }
            }
            if (!ok) {
                fallback(v);
                warm = false;
                continue;
            }
            warm = true;
            // The moments about the reference, then about the vertex.
            double moments[kMoments] = {};  // about the reference, then about the vertex
            for (int dy = -my; dy <= my; ++dy) {
                const int lo = s.lo[std::size_t(dy + my)], hi = s.hi[std::size_t(dy + my)];
                if (lo > hi) continue;
                const double* row_sums =
                    &s.prefix[std::size_t(lr + dy) * std::size_t(cols + 1) * kMoments];
                const double* a = row_sums + std::size_t(lo) * kMoments;
                const double* b = row_sums + std::size_t(hi + 1) * kMoments;
                for (int k = 0; k < kMoments; ++k) moments[k] += b[k] - a[k];
            }
            fit_from_moments(moments, centre, ref, normals[std::size_t(v)], v, body);
        }
    }
}

bool grid_applies(const TriangleMesh& mesh, const ShapeIndexOptions& options) {
    if (options.method == ShapeIndexMethod::mesh || !(options.radius > 0)) return false;
    const bool grid = dem_mesh(mesh);
    if (options.method == ShapeIndexMethod::grid && !grid)
        throw Error("field", "the grid method needs a mesh made from a DEM");
    return grid;
}

// The normals the grid method reads, a band of pixel rows at a time where band_normals
// applies (24 bytes a vertex of the band, not of the mesh: a ladder of radii holds its fits'
// normals beside its own state), else the whole mesh's.
class GridNormals {
  public:
    GridNormals(const TriangleMesh& mesh, const ProgressFn& progress)
        : mesh_(mesh), by_bands_(normals_by_bands(mesh)) {
        if (!by_bands_) normals_.values = vertex_normals(mesh, progress);
    }
    // The normals of (at least) the vertices of pixel rows [r0, r1).
    const Normals& rows(int r0, int r1) {
        if (by_bands_) band_normals(mesh_, r0, r1, normals_);
        return normals_;
    }

  private:
    const TriangleMesh& mesh_;
    bool by_bands_;
    Normals normals_;
};

// The vertices no pixel of g owns (pinched copies, collapsed poles), by their pixel's row.
std::vector<std::int32_t> unowned_vertices(const TriangleMesh& mesh, const GridLayout& g) {
    std::vector<std::int32_t> unowned;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const auto p = std::size_t(mesh.vertex_pixel[v]);
        if (g.vertex_at(int(p % std::size_t(g.width)), int(p / std::size_t(g.width))) !=
            std::int32_t(v))
            unowned.push_back(std::int32_t(v));
    }
    std::stable_sort(unowned.begin(), unowned.end(), [&](std::int32_t a, std::int32_t b) {
        return mesh.vertex_pixel[std::size_t(a)] / g.width <
               mesh.vertex_pixel[std::size_t(b)] / g.width;
    });
    return unowned;
}

// Every vertex once through `body`, by tiles of pixels, a row of tiles at a time; vertices no
// pixel owns and windows the tiles cannot hold take the mesh path, the former after the
// tiles with the normals kept from their row's band.
std::size_t grid_for_each_vertex(const TriangleMesh& mesh, const GridLayout& g,
                                 const ShapeIndexOptions& options, GridNormals& normals,
                                 const ProgressFn& progress, const VertexFn& body) {
    const bool disk = disk_applies(mesh, options);
    const GridLayout* disk_grid = disk ? &g : nullptr;
    tbb::enumerable_thread_specific<GridScratch> scratch;
    tbb::enumerable_thread_specific<std::size_t> fallbacks(0);
    const int tile = disk ? g.disk_tile : kTile;
    const int tile_rows = (g.height + tile - 1) / tile, tile_cols = (g.width + tile - 1) / tile;
    const auto unowned = unowned_vertices(mesh, g);
    std::vector<Vec3> unowned_normals(unowned.size());
    std::size_t next_unowned = 0;
    for (int tr = 0; tr < tile_rows; ++tr) {
        const int r0 = tr * tile, r1 = std::min(g.height, r0 + tile);
        const Normals& band = normals.rows(r0, r1);
        tbb::parallel_for(tbb::blocked_range<int>(0, tile_cols, 1), [&](const auto& r) {
            for (int tc = r.begin(); tc < r.end(); ++tc)
                (disk ? disk_tile : grid_tile)(mesh, g, band, options, r0, tc * tile,
                                               scratch.local(), fallbacks.local(), body);
        });
        for (; next_unowned < unowned.size() &&
               mesh.vertex_pixel[std::size_t(unowned[next_unowned])] / g.width < r1;
             ++next_unowned)
            unowned_normals[next_unowned] = band[std::size_t(unowned[next_unowned])];
        report_progress(progress, double(tr + 1) / tile_rows, "shape index");
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, unowned.size(), 64), [&](const auto& r) {
        auto& s = scratch.local();
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            const auto v = unowned[i];
            PrincipalCurvatures k;
            double scale = 0;
            const bool ok =
                mesh_fit(mesh, v, unowned_normals[i], options, disk_grid, s.mesh, k, scale);
            body(v, ok, k, scale);
        }
    });
    return fallbacks.combine(std::plus<>()) + unowned.size();
}

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
    if (grid) {
        GridNormals normals(mesh, scaled_progress(progress, 0, 0.05));
        const auto layout = grid_layout(mesh, options.disk_tile_angle);
        report_progress(progress, 0.06, "shape index");
        grid_for_each_vertex(mesh, layout, options, normals, scaled_progress(progress, 0.06, 1),
                             body);
        return;
    }
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
