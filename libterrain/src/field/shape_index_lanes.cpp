// The rings window's fit four vertices at a time, in the lanes of vectors
// (fit_curvatures_batch; docs/field.md, "Four vertices at a time").
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "curvature_fit.hpp"
#include "shape_index_fit.hpp"

namespace terrain::field::detail {

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
            const auto& centre = mesh.positions()[std::size_t(batch.vertex[std::size_t(l)])];
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
                const auto& q = mesh.positions()[std::size_t(w)];
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

}  // namespace terrain::field::detail
