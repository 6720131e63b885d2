#pragma once
// The moments of the grid method (the ball window on DEM meshes): the 35 monomials of degree
// <= 4 of an offset, their Taylor shift to a vertex, and the fit's normal equations made
// from them in the vertex's tangent frame (docs/field.md, "Windows and methods").

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>

#include "curvature_fit.hpp"
#include "shape_index_fit.hpp"

namespace terrain::field::detail {

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
inline void monomials(const Vec3& e, double* out) {
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
inline NormalEquations equations_from_moments(const double* m, const Vec3& normal) {
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

}  // namespace terrain::field::detail
