#pragma once
// The tangent-frame fit of the shape index (docs/field.md, "Curvatures"): the normal
// equations of h = a u^2 + b uv + c v^2 (+ d u + e v) and their solution, the principal
// curvatures with their noise. Inline: every method's hot loop calls them once a vertex.

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "terrain/field/shape_index.hpp"

namespace terrain::field::detail {

using Vec3 = std::array<double, 3>;

inline Vec3 sub(const std::array<float, 3>& a, const std::array<float, 3>& b) {
    return {double(a[0]) - b[0], double(a[1]) - b[1], double(a[2]) - b[2]};
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Vec3 normalized(const Vec3& a) {
    const double n = std::sqrt(dot(a, a));
    return n > 0 ? Vec3{a[0] / n, a[1] / n, a[2] / n} : Vec3{0, 0, 1};
}

// The normal equations of the fit h = a u^2 + b uv + c v^2 (+ d u + e v) in raw tangent
// coordinates (lower triangles of ata), the neighbour count m and their mean distance.
struct NormalEquations {
    std::array<std::array<double, 5>, 5> ata{};
    std::array<double, 5> atb{};
    std::size_t m = 0;
    double scale = 0;
};

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

// Solves the fit with coordinates divided by `scale` (so that it is scale-free; dividing only
// rescales the equations) and returns the principal curvatures in units of 1/scale; false
// when the neighbourhood is too small.
inline bool solve_curvatures(NormalEquations e, PrincipalCurvatures& out) {
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
inline std::array<Vec3, 2> tangent_frame(const Vec3& normal) {
    const Vec3 axis = std::abs(normal[0]) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 t1 = normalized(cross(normal, axis));
    return {t1, cross(normal, t1)};
}

// Fits h = a u^2 + b uv + c v^2 (+ d u + e v) to the neighbourhood in the tangent frame of
// `normal`, coordinates divided by their mean distance so the fit is scale-free. Returns
// false when the neighbourhood is too small. Curvatures come back in units of 1/scale.
inline bool fit_curvatures(const TriangleMesh& mesh, std::int32_t v, const Vec3& normal,
                           const std::int32_t* neighbour_ids, std::size_t m,
                           PrincipalCurvatures& out, double& scale) {
    const std::span<const std::int32_t> neighbours(neighbour_ids, m);
    if (m < 3) return false;
    const auto [t1, t2] = tangent_frame(normal);
    // One pass: the normal equations of the raw tangent coordinates and their mean distance.
    const auto& centre = mesh.positions()[v];
    NormalEquations e;
    e.m = m;
    for (auto w : neighbours) {
        const Vec3 d = sub(mesh.positions()[w], centre);
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

}  // namespace terrain::field::detail
