#include "crater_shape.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace terrain::synth {
namespace {

double smoothstep(double e0, double e1, double x) {
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// Polynomial smooth minimum (Quilez): min(a,b) rounded over |a-b| < k, by k/4 where a = b.
double smooth_min(double a, double b, double k) {
    const double h = std::max(k - std::abs(a - b), 0.0) / k;
    return std::min(a, b) - h * h * k * 0.25;
}

}  // namespace

double degradation(double d, double age, double d_half) {
    if (d_half <= 0) return 0;
    const double r = d_half / d;
    return 1.0 - std::exp(-std::numbers::ln2 * age * r * r);
}

void add_crater(Grid& grid, const Geometry& geo, const Crater& c, const Shape& shape) {
    const double q = c.degradation;
    const double radius = 0.5 * c.diameter;
    const double depth = shape.depth_ratio * c.diameter * (1.0 - q);
    const double rim = shape.rim_ratio * c.diameter * std::pow(1.0 - q, 1.5);
    const double rounding = (0.04 + 0.4 * q) * (2.0 * depth + 3.0 * rim);  // smooth_min width
    if (rounding <= 0) return;
    // Both branches meet at rim + rounding/4 at s = 1, so that the rounded crest sits at `rim`
    // and the floor (s = 0) at rim - depth.
    const double lift = 0.25 * rounding;
    const double floor_z = rim - depth;

    const double ce = c.col + geo.margin_x, re = c.row + geo.margin_y;
    const double lat = geo.y_of(re - 0.5) / geo.radius;
    const double kx = geo.east_scale(lat) * geo.pixel;  // ground metres per column
    const double ky = geo.pixel;                        // ground metres per row

    // The old surface's plane from eight points on the rim circle.
    static constexpr double h2 = 0.70710678118654752440;
    static constexpr std::array<std::array<double, 2>, 8> dirs{
        {{1, 0}, {h2, h2}, {0, 1}, {-h2, h2}, {-1, 0}, {-h2, -h2}, {0, -1}, {h2, -h2}}};
    double mean = 0, grad_e = 0, grad_n = 0;
    for (const auto& d : dirs) {
        const double z = grid.sample(ce + radius * d[0] / kx, re - radius * d[1] / ky);
        mean += z;
        grad_e += z * d[0];
        grad_n += z * d[1];
    }
    mean /= 8.0;
    grad_e /= 4.0 * radius;
    grad_n /= 4.0 * radius;

    const double reach = kReach * radius;
    const int r0 = std::max(0, static_cast<int>(std::floor(re - reach / ky - 0.5)));
    const int r1 = std::min(grid.height - 1, static_cast<int>(std::ceil(re + reach / ky - 0.5)));
    const int c0 = std::max(0, static_cast<int>(std::floor(ce - reach / kx - 0.5)));
    const int c1 = std::min(grid.width - 1, static_cast<int>(std::ceil(ce + reach / kx - 0.5)));
    const double inv_r = 1.0 / radius;
    const double erase = 1.0 - q;  // degraded craters let the old surface show through
    for (int row = r0; row <= r1; ++row) {
        const double dn = (re - (row + 0.5)) * ky;
        const double across = reach * reach - dn * dn;
        if (across <= 0) continue;
        // Columns within the reach on this row (one spare column each side; s decides).
        const double half = std::sqrt(across) / kx + 1.0;
        const int first = std::max(c0, static_cast<int>(std::floor(ce - half - 0.5)));
        const int last = std::min(c1, static_cast<int>(std::ceil(ce + half - 0.5)));
        for (int col = first; col <= last; ++col) {
            const double de = (col + 0.5 - ce) * kx;
            const double s = std::sqrt(de * de + dn * dn) * inv_r;
            if (s >= kReach) continue;
            // Away from the rim one branch is lower by more than the rounding width, where
            // smooth_min is exactly min: s <= 0.5 is all bowl, s >= 1.6 all ejecta.
            const double bowl = floor_z + (depth + lift) * s * s;
            double profile = bowl;
            if (s > 0.5) {
                const double t = s;
                double ejecta = (rim + lift) / (t * t * t);
                if (s > kTaperStart) ejecta *= 1.0 - smoothstep(kTaperStart, kReach, s);
                profile = s < 1.6 ? smooth_min(bowl, ejecta, rounding) : ejecta;
            }
            double& z = grid.at(col, row);
            if (s < 1.0) {
                const double plane = mean + grad_e * de + grad_n * dn;
                const double w = erase * (s > 0.7 ? 1.0 - smoothstep(0.7, 1.0, s) : 1.0);
                z += profile + w * (plane - z);
            } else {
                z += profile;
            }
        }
    }
}

}  // namespace terrain::synth
