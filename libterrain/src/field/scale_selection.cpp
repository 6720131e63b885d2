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

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "sample_lattice.hpp"
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

// A vertex's choice along the ladder (docs/field.md, "The choice"). Per vertex, as the rungs
// go up: the previous rung's curvedness and field value, whether the curvedness rose into it,
// the previous rung itself, and the peak chosen so far (its curvedness; whether it is a
// significant one). Curvedness and field values are held in 16 bits (1/4096 and 1/600: far
// finer than the thresholds and the persistence), so that the ladder adds 8 bytes a vertex to
// the field's own 5.
class LadderChoice {
  public:
    LadderChoice(const ShapeIndexOptions& options, ScaleSelectedField& out, std::size_t n)
        : beta_(options.peak_dominance),
          significant_c_(quantize(options.contrast_curvedness, kCurvednessUnit)),
          out_(out),
          previous_c_(n, 0),
          previous_f_(n, 0),
          chosen_c_(n, 0),
          state_(n, kRising) {
        out.field.assign(n, 50.0f);
        out.scale.assign(n, 0);
    }

    // Vertex v's curvedness and field value at `rung`, the rungs in increasing order (a rung
    // may be missing: the vertex's window was skipped there). Each vertex on one thread.
    void climb(std::size_t v, std::uint8_t rung, double cd, double f) {
        const auto c = quantize(cd, kCurvednessUnit);
        if (state_[v] & kSeen) {
            const bool rose = state_[v] & kRising;
            if (rose && c < previous_c_[v])  // the previous rung was a peak
                peak(v, previous_rung(v), previous_c_[v], previous_f_[v], false);
            state_[v] =
                std::uint8_t(c >= previous_c_[v] ? state_[v] | kRising : state_[v] & ~kRising);
        }
        state_[v] = std::uint8_t((state_[v] & 0x0f) | kSeen | (rung << 4));
        previous_c_[v] = c;
        previous_f_[v] = quantize(f, kFieldUnit);
    }

    // The last rung each vertex reached ends its ladder: the ladder's top, or the last rung
    // whose window the tables hold (near a pole, or where a geographic grid's pixels are
    // narrow, the wider ones are skipped). A rise into it is a rise to the top, no peak (with
    // `top`: three rungs or more), for a vertex that sees the whole ladder and for one that
    // does not.
    void finish(bool top) {
        for (std::size_t v = 0; v < state_.size(); ++v)
            if ((state_[v] & kSeen) && (state_[v] & kRising))
                peak(v, previous_rung(v), previous_c_[v], previous_f_[v], top);
    }

  private:
    static constexpr std::uint8_t kRising = 1, kSignificant = 2, kChosen = 4, kSeen = 8;
    static constexpr double kCurvednessUnit = 4096, kFieldUnit = 600;
    static std::uint16_t quantize(double x, double unit) {
        return static_cast<std::uint16_t>(std::clamp(std::lround(x * unit), 0L, 65535L));
    }
    std::uint8_t previous_rung(std::size_t v) const { return std::uint8_t(state_[v] >> 4); }

    // A peak over scale at `rung` (curvedness c, field value f): taken when it is the first
    // significant one (c >= the contrast curvedness), or at least beta times as strong as the
    // one taken, or when no significant one is taken yet and it is stronger than the one
    // taken. A rise that ends at the ladder's top is no peak: the landform is larger than the
    // ladder.
    void peak(std::size_t v, std::uint8_t rung, std::uint16_t c, std::uint16_t f, bool top) {
        const bool significant = c >= significant_c_ && !top;
        const bool chosen = state_[v] & kChosen, chosen_significant = state_[v] & kSignificant;
        bool take = !chosen;
        if (significant)
            take = take || !chosen_significant || c >= beta_ * chosen_c_[v];
        else
            take = take || (!chosen_significant && c > chosen_c_[v]);
        if (!take) return;
        chosen_c_[v] = c;
        out_.scale[v] = rung;
        const float value = float(f / kFieldUnit);
        out_.field[v] = top ? 50.0f + kTopContrast * (value - 50.0f) : value;
        state_[v] =
            std::uint8_t((state_[v] & ~kSignificant) | kChosen | (significant ? kSignificant : 0));
    }

    double beta_;
    std::uint16_t significant_c_;
    ScaleSelectedField& out_;
    std::vector<std::uint16_t> previous_c_, previous_f_, chosen_c_;
    std::vector<std::uint8_t> state_;  // flags below, the previous rung above 4 bits
};

// One rung's scale-normalised curvedness and field value from a fit (docs/field.md, "The
// measure", "Pixel noise", "The value").
struct RungMeasure {
    const TriangleMesh& mesh;
    double radius, noise_threshold, tau2;

    bool operator()(std::int32_t v, bool ok, const PrincipalCurvatures& k, double scale, double& cd,
                    double& f) const {
        if (!ok || !(scale > 0)) return false;
        // Curvatures in 1/m relative to the body's sphere through the vertex (its own convex
        // curvature would otherwise grow into every large window), times the radius:
        // dimensionless, scale-normalised.
        const double body = body_curvature(v);
        const double k1 = (k.k1 / scale - body) * radius, k2 = (k.k2 / scale - body) * radius;
        cd = std::sqrt(0.5 * (k1 * k1 + k2 * k2));
        // The part of the curvedness the DEM's pixel noise does not explain: less
        // kNoiseSigmas times what the noise alone gives this fit, in quadrature.
        const double noisy = noise_threshold * k.noise / (scale * scale) * radius;
        cd = std::sqrt(std::max(0.0, cd * cd - noisy * noisy));
        if (!std::isfinite(cd)) return false;
        const double weight = tau2 > 0 ? cd * cd / (cd * cd + tau2) : 1.0;
        const double si = cd > 0 ? shape_index(k1, k2) : 0.0;
        f = 50.0 * (si * weight + 1.0);
        return true;
    }

    // The curvature the fit gives the sphere through the vertex (its distance from the
    // body's centre) on a body-fixed mesh; 0 on a map.
    double body_curvature(std::int32_t v) const {
        if (mesh.frame != MeshFrame::body) return 0.0;
        const auto& p = mesh.positions()[std::size_t(v)];
        const double x = mesh.origin[0] + p[0], y = mesh.origin[1] + p[1],
                     z = mesh.origin[2] + p[2];
        const double r = std::sqrt(x * x + y * y + z * z);
        return r > 0 ? sphere_curvature_in_fit(r, radius) : 0.0;
    }
};

// One rung of the ladder through `choice`: every vertex fitted, or on a wide rung the
// lattice's vertices fitted and the others interpolated between them.
void climb_rung(const TriangleMesh& mesh, const ShapeIndexOptions& one, const RungMeasure& measure,
                std::uint8_t rung, LadderChoice& choice, const ProgressFn& progress) {
    if (one.sample_stride <= 1) {
        detail::for_each_curvature(
            mesh, one, progress,
            [&](std::int32_t v, bool ok, const PrincipalCurvatures& k, double scale) {
                double cd = 0, f = 0;
                if (measure(v, ok, k, scale, cd, f)) choice.climb(std::size_t(v), rung, cd, f);
            });
        return;
    }
    detail::SampleLattice lattice(mesh.grid_width, mesh.grid_height, one.sample_stride);
    // The lattice's points around the rows asked for: a vertex takes the points of its cell,
    // or past the lattice's ends the last two along a line.
    ShapeIndexOptions around = one;
    const int margin = 2 * one.sample_stride + 1;
    around.first_row = one.first_row > margin ? one.first_row - margin : 0;
    around.end_row = one.end_row < INT32_MAX - margin ? one.end_row + margin : INT32_MAX;
    detail::for_each_curvature(
        mesh, around, scaled_progress(progress, 0, 0.95),
        [&](std::int32_t v, bool ok, const PrincipalCurvatures& k, double scale) {
            double cd = 0, f = 0;
            if (measure(v, ok, k, scale, cd, f))
                lattice.set(mesh.vertex_pixel[std::size_t(v)], float(cd), float(f));
        });
    const std::size_t n = mesh.vertex_count();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& r) {
        for (std::size_t v = r.begin(); v < r.end(); ++v) {
            if (!detail::row_asked(mesh, one, std::int32_t(v))) continue;
            float cd = 0, f = 0;
            if (lattice.at(mesh.vertex_pixel[v], cd, f)) choice.climb(v, rung, cd, f);
        }
    });
    report_progress(progress, 1.0, "shape index");
}

}  // namespace

ScaleSelectedField scale_selected_shape_index(const TriangleMesh& mesh,
                                              const ShapeIndexOptions& options,
                                              const ProgressFn& progress) {
    ScaleSelectedField out;
    out.radii = checked_ladder(mesh, options);
    out.pixel_noise_m = pixel_noise(mesh);
    LadderChoice choice(options, out, mesh.vertex_count());
    const double tau2 = options.contrast_curvedness * options.contrast_curvedness;
    const double spacing = std::sqrt(mean_vertex_area(mesh));
    const std::size_t rungs = out.radii.size();
    for (std::size_t i = 0; i < rungs; ++i) {
        ShapeIndexOptions one = options;
        one.auto_scale = false;
        one.radius = out.radii[i];
        one.window = ShapeIndexWindow::disk;
        one.skip_wide = i > 0;
        one.disk_tile_angle = kLadderTileAngle;
        // Wide rungs on a lattice (sample_lattice.hpp), but the top: the quiet plains end
        // there, and on a lattice their regions' boundaries ran along its lines in steps.
        one.sample_stride = i + 1 < rungs ? detail::rung_stride(out.radii[i] / spacing) : 1;
        const RungMeasure measure{mesh, out.radii[i], kNoiseSigmas * out.pixel_noise_m, tau2};
        climb_rung(
            mesh, one, measure, std::uint8_t(i), choice,
            scaled_progress(progress, double(i) / double(rungs), double(i + 1) / double(rungs)));
    }
    choice.finish(rungs >= 3);
    report_progress(progress, 1.0, "shape index");
    return out;
}

}  // namespace terrain::field
