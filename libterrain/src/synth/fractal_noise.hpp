#pragma once
// Private: fractal roughness, octaves of value noise (smoothly interpolated random lattice
// values) whose amplitude falls as wavelength^hurst, a self-affine surface (Turcotte 1997,
// ch. 7).
#include "deterministic.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace terrain::synth {

// One octave: a random lattice of spacing `wavelength`, rotated and shifted so that no
// direction dominates, its values tabulated over the area where it is evaluated.
class Octave {
  public:
    Octave(std::uint64_t key, double wavelength, double amplitude, double angle, double shift_u,
           double shift_v)
        : key_(key),
          inv_wavelength_(1.0 / wavelength),
          amplitude_(amplitude),
          cos_(std::cos(angle)),
          sin_(std::sin(angle)),
          shift_u_(shift_u),
          shift_v_(shift_v) {}

    // Tabulates the lattice over the rectangle [x0,x1] x [y0,y1] of projected metres.
    void tabulate(double x0, double x1, double y0, double y1);

    // Value noise: the lattice values interpolated with the quintic fade, times the amplitude.
    double operator()(double x, double y) const {
        const double uu = u(x, y), vv = v(x, y);
        const double fu = std::floor(uu), fv = std::floor(vv);
        const std::int64_t i =
            std::clamp(static_cast<std::int64_t>(fu) - u0_, std::int64_t{0}, nu_ - 2);
        const std::int64_t j =
            std::clamp(static_cast<std::int64_t>(fv) - v0_, std::int64_t{0}, nv_ - 2);
        const double* row0 = table_.data() + j * nu_ + i;
        const double* row1 = row0 + nu_;
        const double su = fade(uu - fu), sv = fade(vv - fv);
        const double a = row0[0] + su * (row0[1] - row0[0]);
        const double b = row1[0] + su * (row1[1] - row1[0]);
        return amplitude_ * (a + sv * (b - a));
    }

  private:
    static double fade(double t) {
        return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    }  // C2 quintic
    double u(double x, double y) const {
        return (cos_ * x - sin_ * y) * inv_wavelength_ + shift_u_;
    }
    double v(double x, double y) const {
        return (sin_ * x + cos_ * y) * inv_wavelength_ + shift_v_;
    }

    std::uint64_t key_;
    double inv_wavelength_, amplitude_, cos_, sin_, shift_u_, shift_v_;
    std::int64_t u0_ = 0, v0_ = 0, nu_ = 0, nv_ = 0;
    std::vector<double> table_;
};

// Octaves from `longest` metres down to two pixels, amplitude falling as wavelength^hurst;
// those longer than `cutoff` are left out. Tabulated over [x0,x1] x [y0,y1].
std::vector<Octave> make_octaves(std::uint64_t seed, double amplitude_at_longest, double longest,
                                 double cutoff, double hurst, double pixel, double x0, double x1,
                                 double y0, double y1);

// The sum of the octaves at (x,y).
inline double fractal(const std::vector<Octave>& octaves, double x, double y) {
    double z = 0;
    for (const auto& octave : octaves) z += octave(x, y);
    return z;
}

}  // namespace terrain::synth
