// The shape index at the scale chosen per vertex (`--radius auto`; docs/field.md, "Scale
// chosen per vertex"): the disk window's fit over a ladder of radii, each vertex taking the
// radius where its scale-normalised curvedness peaks (Lindeberg's automatic scale selection,
// with curvedness x radius as the normalised measure: the same for a bowl of any size with
// the same depth-to-diameter ratio).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "shape_index_fit.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/shape_index.hpp"

namespace terrain::field {
namespace {

constexpr std::size_t kMaxRadii = 16;  // (a rung in 4 bits)
// The contrast kept by a vertex whose curvedness rises to the ladder's top: a landform wider
// than the ladder reads nearly planar, without making plateaus of exactly equal values.
constexpr float kTopContrast = 0.25f;
// A curvature is seen at a rung only when it is this many times the spread (standard
// deviation) of the curvedness the DEM's pixel noise alone gives that rung's fit.
constexpr double kNoiseSigmas = 3;
// The most pixels pixel_noise samples.
constexpr std::size_t kNoiseSamples = std::size_t(1) << 20;
// The disk fit's bias on a sphere (sphere_curvature_in_fit): a quadratic fitted over a disk
// of radius R to a sphere of radius r has the curvature 1/r (1 + k (R/r)^2). A uniform disk
// in angle gives k = 3/16 from the sphere's quartic term; the grid's pixels and the tile's
// tilt make it 0.13-0.16 within 45 degrees of the equator (tests/field/scale_selection.cpp).
constexpr double kSphereFitBias = 0.14;
// The ladder's largest radius on a body, as a share of its radius: a wider window is no
// longer a local shape (the sphere departs from the fit's quadratic by more than it can
// correct).
constexpr double kLadderBodyShare = 0.5;
// The ladder's tiles of sums may span this angle on the body (shape_index.hpp): the tilt of a
// tile's frame is a slope, which the fit takes up, not a curvature.
constexpr double kLadderTileAngle = 0.4;

void check_dem_mesh(const TriangleMesh& mesh) {
    if (mesh.grid_width <= 0 || mesh.grid_height <= 0 ||
        mesh.vertex_pixel.size() != mesh.vertex_count())
        throw Error("field",
                    "--radius auto chooses the scale on a DEM's grid; a mesh read from a file "
                    "takes --rings or --radius");
}

}  // namespace

double pixel_noise(const TriangleMesh& mesh) {
    const int w = mesh.grid_width, h = mesh.grid_height;
    if (w < 3 || h < 3 || mesh.pixel_vertex.size() != std::size_t(w) * std::size_t(h)) return 0;
    const std::size_t inner = std::size_t(w - 2) * std::size_t(h - 2);
    const std::size_t stride = std::max<std::size_t>(1, inner / kNoiseSamples);
    std::vector<double> response;
    response.reserve(std::min(inner, kNoiseSamples + 1));
    static constexpr double kMask[3] = {1, -2, 1};
    for (std::size_t i = 0; i < inner; i += stride) {
        const int col = 1 + int(i % std::size_t(w - 2)), row = 1 + int(i / std::size_t(w - 2));
        const auto at = [&](int c, int r) {
            return mesh.pixel_vertex[std::size_t(r) * std::size_t(w) + std::size_t(c)];
        };
        const auto centre = at(col, row);
        if (centre < 0) continue;
        const auto p0 = mesh.position(std::size_t(centre));
        std::array<double, 3> up{0, 0, 1};
        if (mesh.frame == MeshFrame::body) {
            const double r = std::hypot(p0[0], p0[1], p0[2]);
            if (!(r > 0)) continue;
            up = {p0[0] / r, p0[1] / r, p0[2] / r};
        }
        double sum = 0;
        bool whole = true;
        for (int dr = -1; dr <= 1 && whole; ++dr)
            for (int dc = -1; dc <= 1; ++dc) {
                const auto v = at(col + dc, row + dr);
                if (v < 0) {
                    whole = false;
                    break;
                }
                const auto p = mesh.position(std::size_t(v));
                const double height =
                    (p[0] - p0[0]) * up[0] + (p[1] - p0[1]) * up[1] + (p[2] - p0[2]) * up[2];
                sum += kMask[dc + 1] * kMask[dr + 1] * height;
            }
        if (whole && std::isfinite(sum)) response.push_back(std::abs(sum));
    }
    if (response.size() < 9) return 0;
    const auto mid = response.begin() + std::ptrdiff_t(response.size() / 2);
    std::nth_element(response.begin(), mid, response.end());
    // |N * z| of white noise is half-normal with sigma 6 sigma_z; its median is 0.6745 of that.
    return *mid / (6 * 0.674489750196082);
}

double sphere_curvature_in_fit(double sphere_radius, double window_radius) {
    const double share = window_radius / sphere_radius;
    return (1 + kSphereFitBias * share * share) / sphere_radius;
}

std::vector<double> default_radii(const TriangleMesh& mesh) {
    check_dem_mesh(mesh);
    const double spacing = std::sqrt(mean_vertex_area(mesh));
    if (!(spacing > 0) || !std::isfinite(spacing))
        throw Error("field", "--radius auto needs a mesh with a positive area");
    // At least the first two rungs, so that even a small tile has a choice; on a body, none
    // wider than half its radius.
    double limit = std::max(4.0, 0.5 * std::min(mesh.grid_width, mesh.grid_height));
    if (mesh.frame == MeshFrame::body && mesh.body.semi_minor_axis() > 0)
        limit = std::min(limit, kLadderBodyShare * mesh.body.semi_minor_axis() / spacing);
    // A rung whose window would reach beyond the tables at a typical place (pixels longer than
    // wide, a geographic tile far from the equator) comes down to their reach, the ladder's
    // last; within a quarter of the rung below, it is left out. Past the reach a rung would
    // be skipped at most vertices, and is refused if given with --radii.
    const double per_metre = detail::typical_disk_reach(mesh, 1.0);
    const double top =
        per_metre > 0 ? detail::kMaxReach / per_metre : std::numeric_limits<double>::infinity();
    std::vector<double> radii;
    for (double pixels = 2; pixels <= 128 && (pixels <= limit || radii.size() < 2); pixels *= 2) {
        const double radius = pixels * spacing;
        if (radius > top && radii.size() >= 2) {
            if (top >= 1.25 * radii.back()) radii.push_back(top);
            break;
        }
        radii.push_back(radius);
    }
    return radii;
}

namespace {

// The ladder of a scale-selected field (options.radii, or the mesh's default_radii), checked
// with the options that choose along it.
std::vector<double> checked_ladder(const TriangleMesh& mesh, const ShapeIndexOptions& options) {
    auto radii = options.radii.empty() ? default_radii(mesh) : options.radii;
    check_dem_mesh(mesh);
    if (radii.empty() || radii.size() > kMaxRadii)
        throw Error("field", "--radii takes 1 to " + std::to_string(kMaxRadii) + " radii");
    for (std::size_t i = 0; i < radii.size(); ++i)
        if (!(radii[i] > 0) || !std::isfinite(radii[i]) || (i > 0 && !(radii[i] > radii[i - 1])))
            throw Error("field", "--radii must be positive metres in increasing order");
    // A rung the disk window's tables cannot hold would be cut to them at the first rung and
    // skipped at the others, on most vertices (the default ladder stays within them).
    if (!options.radii.empty()) detail::check_window_reach(mesh, radii.back(), "--radii");
    if (!(options.contrast_curvedness >= 0) || !std::isfinite(options.contrast_curvedness))
        throw Error("field", "the contrast curvedness must be a number >= 0");
    if (!(options.peak_dominance >= 1) || !std::isfinite(options.peak_dominance))
        throw Error("field", "the peak dominance must be a number >= 1");
    return radii;
}

}  // namespace

ScaleSelectedField scale_selected_shape_index(const TriangleMesh& mesh,
                                              const ShapeIndexOptions& options,
                                              const ProgressFn& progress) {
    ScaleSelectedField out;
    out.radii = checked_ladder(mesh, options);
    const std::size_t n = mesh.vertex_count();
    const double tau2 = options.contrast_curvedness * options.contrast_curvedness;
    const double beta = options.peak_dominance;
    const double sig = options.contrast_curvedness;
    // The curvature the fit of `radius` gives the sphere through the vertex (its distance from
    // the body's centre) on a body-fixed mesh; 0 on a map.
    const auto body_curvature = [&](std::int32_t v, double radius) {
        if (mesh.frame != MeshFrame::body) return 0.0;
        const auto& p = mesh.positions()[std::size_t(v)];
        const double x = mesh.origin[0] + p[0], y = mesh.origin[1] + p[1],
                     z = mesh.origin[2] + p[2];
        const double r = std::sqrt(x * x + y * y + z * z);
        return r > 0 ? sphere_curvature_in_fit(r, radius) : 0.0;
    };
    // Per vertex, as the rungs go up: the previous rung's curvedness and field value, whether
    // the curvedness rose into it, the previous rung itself, and the peak chosen so far (its
    // curvedness; whether it is a significant one). Curvedness and field values are held in
    // 16 bits (1/4096 and 1/600: far finer than the thresholds and the persistence), so that
    // the ladder adds 8 bytes a vertex to the field's own 5.
    constexpr std::uint8_t kRising = 1, kSignificant = 2, kChosen = 4, kSeen = 8;
    const auto quantize = [](double x, double unit) {
        return static_cast<std::uint16_t>(std::clamp(std::lround(x * unit), 0L, 65535L));
    };
    constexpr double kCurvednessUnit = 4096, kFieldUnit = 600;
    std::vector<std::uint16_t> previous_c(n, 0), previous_f(n, 0), chosen_c(n, 0);
    std::vector<std::uint8_t> state(n, kRising);  // flags below, the previous rung above 4 bits
    const auto previous_rung = [&](std::size_t v) { return std::uint8_t(state[v] >> 4); };
    out.field.assign(n, 50.0f);
    out.scale.assign(n, 0);
    out.pixel_noise_m = pixel_noise(mesh);
    const double noise_threshold = kNoiseSigmas * out.pixel_noise_m;
    const std::size_t rungs = out.radii.size();
    const std::uint16_t significant_c = quantize(sig, kCurvednessUnit);
    // A peak over scale at rung `rung` (curvedness c, field value f): taken when it is the
    // first significant one (c >= sig), or at least beta times as strong as the one taken, or
    // when no significant one is taken yet and it is stronger than the one taken. A rise
    // that ends at the ladder's top is no peak: the landform is larger than the ladder.
    const auto peak = [&](std::size_t v, std::uint8_t rung, std::uint16_t c, std::uint16_t f,
                          bool top) {
        const bool significant = c >= significant_c && !top;
        const bool chosen = state[v] & kChosen, chosen_significant = state[v] & kSignificant;
        bool take = !chosen;
        if (significant)
            take = take || !chosen_significant || c >= beta * chosen_c[v];
        else
            take = take || (!chosen_significant && c > chosen_c[v]);
        if (!take) return;
        chosen_c[v] = c;
        out.scale[v] = rung;
        const float value = float(f / kFieldUnit);
        out.field[v] = top ? 50.0f + kTopContrast * (value - 50.0f) : value;
        state[v] =
            std::uint8_t((state[v] & ~kSignificant) | kChosen | (significant ? kSignificant : 0));
    };
    const auto steps = double(rungs);
    for (std::size_t i = 0; i < rungs; ++i) {
        ShapeIndexOptions one = options;
        one.auto_scale = false;
        one.radius = out.radii[i];
        one.window = ShapeIndexWindow::disk;
        one.skip_wide = i > 0;
        one.disk_tile_angle = kLadderTileAngle;
        const double radius = out.radii[i];
        const auto rung = static_cast<std::uint8_t>(i);
        detail::for_each_curvature(
            mesh, one, scaled_progress(progress, double(i) / steps, double(i + 1) / steps),
            [&](std::int32_t vi, bool ok, const PrincipalCurvatures& k, double scale) {
                if (!ok || !(scale > 0)) return;
                const auto v = std::size_t(vi);
                // Curvatures in 1/m relative to the body's sphere through the vertex (its own
                // convex curvature would otherwise grow into every large window), times the
                // radius: dimensionless, scale-normalised.
                const double body = body_curvature(vi, radius);
                const double k1 = (k.k1 / scale - body) * radius,
                             k2 = (k.k2 / scale - body) * radius;
                double cd = std::sqrt(0.5 * (k1 * k1 + k2 * k2));
                // The part of the curvedness the DEM's pixel noise does not explain: less
                // kNoiseSigmas times what the noise alone gives this fit, in quadrature.
                const double noisy = noise_threshold * k.noise / (scale * scale) * radius;
                cd = std::sqrt(std::max(0.0, cd * cd - noisy * noisy));
                if (!std::isfinite(cd)) return;
                const auto c = quantize(cd, kCurvednessUnit);
                const double weight = tau2 > 0 ? cd * cd / (cd * cd + tau2) : 1.0;
                const double si = cd > 0 ? shape_index(k1, k2) : 0.0;
                const auto f = quantize(50.0 * (si * weight + 1.0), kFieldUnit);
                if (state[v] & kSeen) {
                    const bool rose = state[v] & kRising;
                    if (rose && c < previous_c[v])  // the previous rung was a peak
                        peak(v, previous_rung(v), previous_c[v], previous_f[v], false);
                    state[v] =
                        std::uint8_t(c >= previous_c[v] ? state[v] | kRising : state[v] & ~kRising);
                }
                state[v] = std::uint8_t((state[v] & 0x0f) | kSeen | (rung << 4));
                previous_c[v] = c;
                previous_f[v] = f;
            });
    }
    // The last rung each vertex reached ends its ladder: the ladder's top, or the last rung
    // whose window the tables hold (near a pole, or where a geographic grid's pixels are
    // narrow, the wider ones are skipped). A rise into it is a rise to the top, no peak, for
    // a vertex that sees the whole ladder and for one that does not (with three rungs or
    // more).
    const bool top = rungs >= 3;
    for (std::size_t v = 0; v < n; ++v)
        if ((state[v] & kSeen) && (state[v] & kRising))
            peak(v, previous_rung(v), previous_c[v], previous_f[v], top);
    report_progress(progress, 1.0, "shape index");
    return out;
}

}  // namespace terrain::field
