#pragma once
// Private: random numbers for the synthetic tile. splitmix64 (Steele, Lea & Flood 2014) with
// a 53-bit uniform double, so that the same seed gives the same numbers with any compiler and
// standard library (no std:: distributions).
#include "deterministic.hpp"

#include <cstdint>

namespace terrain::synth {

// splitmix64's output function: a bijective 64-bit mix.
inline std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

// The top 53 bits as a double in [0,1).
inline double to_unit(std::uint64_t bits) {
    return static_cast<double>(bits >> 11) * 0x1.0p-53;
}

class Rng {
  public:
    explicit Rng(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next() {
        state_ += 0x9e3779b97f4a7c15ULL;
        return mix64(state_);
    }
    double uniform() { return to_unit(next()); }                                 // [0,1)
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }  // [lo,hi)

  private:
    std::uint64_t state_;
};

// Independent random streams derived from the seed.
enum Stream : std::uint64_t { kPopulation = 1, kRelief = 2, kRoughness = 3, kRegolith = 4 };

inline std::uint64_t stream_seed(std::uint64_t seed, Stream stream) {
    return mix64(seed ^ mix64(0x632be59bd9b4e019ULL * static_cast<std::uint64_t>(stream)));
}

}  // namespace terrain::synth
