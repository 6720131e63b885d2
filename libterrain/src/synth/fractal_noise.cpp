#include "fractal_noise.hpp"

#include <limits>
#include <numbers>

#include "random.hpp"

namespace terrain::synth {
namespace {

double lattice_value(std::uint64_t key, std::int64_t ix, std::int64_t iy) {
    const std::uint64_t h =
        mix64(key ^ mix64(static_cast<std::uint64_t>(ix) * 0x9e3779b97f4a7c15ULL +
                          static_cast<std::uint64_t>(iy)));
    return 2.0 * to_unit(h) - 1.0;  // [-1,1)
}

}  // namespace

void Octave::tabulate(double x0, double x1, double y0, double y1) {
    double u_lo = std::numeric_limits<double>::infinity(), u_hi = -u_lo;
    double v_lo = u_lo, v_hi = -u_lo;
    for (double x : {x0, x1})
        for (double y : {y0, y1}) {
            u_lo = std::min(u_lo, u(x, y));
            u_hi = std::max(u_hi, u(x, y));
            v_lo = std::min(v_lo, v(x, y));
            v_hi = std::max(v_hi, v(x, y));
        }
    u0_ = static_cast<std::int64_t>(std::floor(u_lo)) - 1;
    v0_ = static_cast<std::int64_t>(std::floor(v_lo)) - 1;
    nu_ = static_cast<std::int64_t>(std::floor(u_hi)) + 3 - u0_;
    nv_ = static_cast<std::int64_t>(std::floor(v_hi)) + 3 - v0_;
    table_.resize(static_cast<std::size_t>(nu_ * nv_));
    for (std::int64_t j = 0; j < nv_; ++j)
        for (std::int64_t i = 0; i < nu_; ++i)
            table_[static_cast<std::size_t>(j * nu_ + i)] = lattice_value(key_, u0_ + i, v0_ + j);
}

std::vector<Octave> make_octaves(std::uint64_t seed, double amplitude_at_longest, double longest,
                                 double cutoff, double hurst, double pixel, double x0, double x1,
                                 double y0, double y1) {
    std::vector<Octave> octaves;
    if (amplitude_at_longest <= 0) return octaves;
    Rng rng(seed);
    for (double wavelength = longest; wavelength >= 2.0 * pixel; wavelength *= 0.5) {
        const double angle = rng.uniform(0.0, 2.0 * std::numbers::pi);
        const std::uint64_t key = rng.next();
        const double shift_u = rng.uniform(0.0, 1024.0), shift_v = rng.uniform(0.0, 1024.0);
        if (wavelength > cutoff) continue;
        octaves.emplace_back(key, wavelength,
                             amplitude_at_longest * std::pow(wavelength / longest, hurst), angle,
                             shift_u, shift_v);
        octaves.back().tabulate(x0, x1, y0, y1);
    }
    return octaves;
}

}  // namespace terrain::synth
