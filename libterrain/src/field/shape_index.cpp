#include "terrain/field/shape_index.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <span>

#include "terrain/core/error.hpp"

namespace terrain::field {
namespace {

using Vec3 = std::array<double, 3>;

Vec3 sub(const std::array<float, 3>& a, const std::array<float, 3>& b) {
    return {double(a[0]) - b[0], double(a[1]) - b[1], double(a[2]) - b[2]};
}
Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec3 normalized(const Vec3& a) {
    const double n = std::sqrt(dot(a, a));
    return n > 0 ? Vec3{a[0] / n, a[1] / n, a[2] / n} : Vec3{0, 0, 1};
}

// Area-weighted vertex normals; triangles are counter-clockwise seen from outside/above.
std::vector<Vec3> vertex_normals(const TriangleMesh& mesh) {
    std::vector<Vec3> normals(mesh.vertex_count(), Vec3{0, 0, 0});
    for (const auto& t : mesh.triangles) {
        const auto& p = mesh.positions;
        const Vec3 n = cross(sub(p[t[1]], p[t[0]]), sub(p[t[2]], p[t[0]]));
        for (auto v : t)
            for (int k = 0; k < 3; ++k) normals[v][k] += n[k];
    }
    for (auto& n : normals) n = normalized(n);
    return normals;
}

struct Scratch {
    std::vector<std::uint32_t> stamp;
    std::uint32_t current = 0;
    std::vector<std::int32_t> gathered;
};

// The neighbourhood of v (gathered[0] is v itself): `rings` rings of mesh edges, or everything
// within `radius` metres reachable through vertices within it.
void gather(const TriangleMesh& mesh, std::int32_t v, const ShapeIndexOptions& options,
            Scratch& s) {
    if (s.stamp.size() != mesh.vertex_count()) s.stamp.assign(mesh.vertex_count(), 0);
    if (++s.current == 0) {
        std::fill(s.stamp.begin(), s.stamp.end(), 0);
        s.current = 1;
    }
    s.gathered.clear();
    s.stamp[v] = s.current;
    const auto& centre = mesh.positions[v];
    const double r2 = options.radius * options.radius;
    std::size_t begin = 0;
    s.gathered.push_back(v);
    for (int ring = 0; options.radius > 0 || ring < options.rings; ++ring) {
        const std::size_t end = s.gathered.size();
        if (begin == end) break;
        for (std::size_t i = begin; i < end; ++i) {
            const auto u = s.gathered[i];
            for (auto k = mesh.neighbor_offsets[u]; k < mesh.neighbor_offsets[u + 1]; ++k) {
                const auto w = mesh.neighbors[k];
                if (s.stamp[w] == s.current) continue;
                s.stamp[w] = s.current;
                if (options.radius > 0) {
                    const Vec3 d = sub(mesh.positions[w], centre);
                    if (dot(d, d) > r2) continue;
                }
                s.gathered.push_back(w);
            }
        }
        begin = end;
    }
}

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

// Fits h = a u^2 + b uv + c v^2 (+ d u + e v) to the neighbourhood in the tangent frame of
// `normal`, coordinates divided by their mean distance so the fit is scale-free. Returns
// false when the neighbourhood is too small. Curvatures come back in units of 1/scale.
bool fit_curvatures(const TriangleMesh& mesh, std::int32_t v, const Vec3& normal,
                    const std::int32_t* neighbour_ids, std::size_t m, PrincipalCurvatures& out,
                    double& scale) {
    const std::span<const std::int32_t> neighbours(neighbour_ids, m);
    if (m < 3) return false;
    const Vec3 axis = std::abs(normal[0]) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 t1 = normalized(cross(normal, axis));
    const Vec3 t2 = cross(normal, t1);
    // One pass: the normal equations of the raw tangent coordinates and their mean
    // distance; dividing coordinates by that distance then only rescales the equations.
    const auto& centre = mesh.positions[v];
    std::array<std::array<double, 5>, 5> ata{};
    std::array<double, 5> atb{};
    scale = 0;
    for (auto w : neighbours) {
        const Vec3 d = sub(mesh.positions[w], centre);
        const double u = dot(d, t1), s = dot(d, t2), h = dot(d, normal);
        scale += std::sqrt(u * u + s * s + h * h);
        const double row[5] = {u * u, u * s, s * s, u, s};
        for (int i = 0; i < 5; ++i) {
            for (int j = 0; j <= i; ++j) ata[i][j] += row[i] * row[j];
            atb[i] += row[i] * h;
        }
    }
    scale /= double(m);
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
        }
    }
    if (!full) {
        std::array<std::array<double, 3>, 3> A{};
        std::array<double, 3> B{atb[0], atb[1], atb[2]};
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j <= i; ++j) A[i][j] = ata[i][j];
        if (!solve_spd<3>(A, B)) return false;
        a = B[0], b = B[1], c = B[2];
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

template <class Body>
void for_each_vertex(const TriangleMesh& mesh, const ShapeIndexOptions& options,
                     const ProgressFn& progress, Body body) {
    if (options.radius <= 0 && options.rings < 1)
        throw Error("field", "--rings must be at least 1");
    if (options.radius < 0 || !std::isfinite(options.radius))
        throw Error("field", "--radius must be a positive number of metres");
    const auto normals = vertex_normals(mesh);
    const auto n = static_cast<std::int32_t>(mesh.vertex_count());
    tbb::enumerable_thread_specific<Scratch> scratch;
    const std::int32_t chunk = 1 << 16;
    for (std::int32_t start = 0; start < n; start += chunk) {
        const std::int32_t stop = std::min(n, start + chunk);
        tbb::parallel_for(tbb::blocked_range<std::int32_t>(start, stop, 512), [&](const auto& r) {
            Scratch& s = scratch.local();
            for (std::int32_t v = r.begin(); v < r.end(); ++v) {
                gather(mesh, v, options, s);
                PrincipalCurvatures k;
                double scale = 0;
                const bool ok = fit_curvatures(mesh, v, normals[v], s.gathered.data() + 1,
                                               s.gathered.size() - 1, k, scale);
                body(v, ok, k, scale);
            }
        });
        report_progress(progress, double(stop) / n, "shape index");
    }
}

}  // namespace

double shape_index(double k1, double k2) {
    if (k1 < k2) std::swap(k1, k2);
    if (k1 == 0 && k2 == 0) return 0.0;
    return 2.0 / std::numbers::pi * std::atan2(k1 + k2, k1 - k2);
}

std::vector<PrincipalCurvatures> principal_curvatures(const TriangleMesh& mesh,
                                                      const ShapeIndexOptions& options,
                                                      const ProgressFn& progress) {
    std::vector<PrincipalCurvatures> out(mesh.vertex_count());
    for_each_vertex(mesh, options, progress,
                    [&](std::int32_t v, bool ok, const PrincipalCurvatures& k, double scale) {
                        if (ok) out[v] = {k.k1 / scale, k.k2 / scale};
                    });
    return out;
}

std::vector<float> shape_index_field(const TriangleMesh& mesh, const ShapeIndexOptions& options,
                                     const ProgressFn& progress) {
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
        for (std::size_t v = 0; v < field.size(); ++v) {
            if (field[v] != kUnknown) continue;
            double sum = 0;
            int count = 0;
            for (auto k = mesh.neighbor_offsets[v]; k < mesh.neighbor_offsets[v + 1]; ++k)
                if (field[mesh.neighbors[k]] != kUnknown) sum += field[mesh.neighbors[k]], ++count;
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
