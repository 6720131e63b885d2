#pragma once
// Private: the DEM's values packed as floats while the stages that do not read them run
// (pipeline::segment; docs/performance.md).
#include <cmath>
#include <cstddef>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/internal/core/parked_arrays.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/release.hpp"

namespace terrain::pipeline::internal {

// The DEM's values held as floats while the stages that do not read them run, when every
// value is one exactly (16- and 32-bit samples, and integers times a power of two below 2^24
// of them): 4 bytes a pixel less. They are doubles again, the same numbers, where they are
// read (the placing of the positions, the region graph's points); a DEM with a value no float
// holds keeps its doubles. Packed again later, the values are not checked again.
// Packing an array already packed does nothing.
class PackedHeights {
  public:
    void pack(Dem& dem, const ProgressFn& progress) {
        const std::size_t n = dem.values.size();
        if (packed_ || !exact(dem, scaled_progress(progress, 0, 0.4))) return;
        const detail::PassProgress packed(progress, 0.4, 1, "mesh");
        values_.reserve(n);
        for (std::size_t i = 0; i < n; ++i) {
            packed.at(i, n);
            values_.push_back(static_cast<float>(dem.values[i]));
        }
        detail::release(dem.values);
        packed_ = true;
    }
    bool packed() const { return packed_; }
    // The values as floats, while packed (and not parked).
    const std::vector<float>& values() const { return values_; }
    // Whether every value is a float (checked once).
    bool exact(const Dem& dem, const ProgressFn& progress = {}) {
        if (checked_) return exact_;
        const std::size_t n = dem.values.size();
        const detail::PassProgress checked(progress, 0, 1, "mesh");
        checked_ = true;
        for (std::size_t i = 0; i < n; ++i) {
            checked.at(i, n);
            const double v = dem.values[i];
            if (!std::isnan(v) && static_cast<double>(static_cast<float>(v)) != v) return false;
        }
        return exact_ = true;
    }
    // The bytes of the values once packed (when they can be).
    std::size_t packed_bytes(const Dem& dem) {
        if (packed_) return values_.size() * sizeof(float);
        return dem.values.size() * (exact(dem) ? sizeof(float) : sizeof(double));
    }
    // The bytes of the DEM's values as held now.
    std::size_t bytes(const Dem& dem) const {
        return packed_ ? values_.size() * sizeof(float) : dem.values.size() * sizeof(double);
    }
    // The floats parked (parked_arrays.hpp) and read back.
    bool park(detail::ParkedArrays& parked, const ProgressFn& progress) {
        return packed_ && parked.park(values_, progress, 0, 1);
    }
    void restore(detail::ParkedArrays& parked, const ProgressFn& progress) {
        if (packed_) parked.restore(values_, progress, 0, 1);
    }
    void unpack(Dem& dem, const ProgressFn& progress) {
        if (!packed_) return;
        const std::size_t n = values_.size();
        const detail::PassProgress unpacked(progress, 0, 1, "mesh");
        dem.values.reserve(n);
        for (std::size_t i = 0; i < n; ++i) {
            unpacked.at(i, n);
            dem.values.push_back(static_cast<double>(values_[i]));
        }
        detail::release(values_);
        packed_ = false;
    }

  private:
    std::vector<float> values_;
    bool packed_ = false;
    bool checked_ = false, exact_ = false;  // every value is a float
};

}  // namespace terrain::pipeline::internal
