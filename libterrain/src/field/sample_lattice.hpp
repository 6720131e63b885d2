// The lattice of pixels a wide rung of the scale-selected field is fitted on, and the
// interpolation between them (docs/field.md, "Scale chosen per vertex": "Wide rungs").
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "shape_index_fit.hpp"

namespace terrain::field::detail {

// A wide rung's field varies over its radius: it is fitted on a lattice of pixels a
// kRadiusPerSample-th of its radius apart (a power of two) and interpolated between them.
constexpr double kRadiusPerSample = 8;

inline int rung_stride(double radius_pixels) {
    int stride = 1;
    while (2 * stride * kRadiusPerSample <= radius_pixels) stride *= 2;
    return stride;
}

// A wide rung's curvedness and field value on the lattice of sampled pixels (every stride-th
// column and row, and the grid's last ones: sampled_pixel), interpolated at any pixel by
// Catmull-Rom cubics through the 4 x 4 lattice points around it: continuous in slope, where
// bilinear interpolation has kinks along the lattice's lines that put the field's ridges and
// troughs there. (Either way a weak field's extrema sit on lattice points, so the ladder's
// top rung, where the quiet plains end, is not fitted on a lattice: scale_selection.cpp.)
// Where one of the 16 points has no value (NoData, a window
// the tables cannot hold), or in the last, narrower cell of a grid whose size is off the
// stride, the cell's corners that have one are weighed bilinearly.
class SampleLattice {
  public:
    SampleLattice(int width, int height, int stride)
        : width_(width),
          height_(height),
          stride_(stride),
          cols_(points(width)),
          rows_(points(height)),
          c_(std::size_t(cols_) * std::size_t(rows_), 0.0f),
          f_(c_.size(), 0.0f),
          has_(c_.size(), 0) {}

    // The values of a sampled pixel (others are ignored).
    void set(std::int64_t pixel, float c, float f) {
        const int col = int(pixel % width_), row = int(pixel / width_);
        if (!sampled_pixel(col, row, stride_, width_, height_)) return;
        const std::size_t k = index(col, row);
        c_[k] = c, f_[k] = f, has_[k] = 1;
    }

    // The values at a pixel (the curvedness at least 0, the field value within [0, 100]);
    // false when no corner of its cell has one.
    bool at(std::int64_t pixel, float& c, float& f) const {
        const int col = int(pixel % width_), row = int(pixel / width_);
        const Taps x = taps(col, width_, cols_, true), y = taps(row, height_, rows_, true);
        double sc = 0, sf = 0;
        bool whole = true;
        for (int j = 0; j < y.count && whole; ++j)
            for (int i = 0; i < x.count; ++i) {
                const std::size_t k = point(x.index[i], y.index[j]);
                if (!has_[k]) {
                    whole = false;
                    break;
                }
                const double w = x.weight[i] * y.weight[j];
                sc += w * c_[k], sf += w * f_[k];
            }
        if (!whole) {
            const Taps lx = taps(col, width_, cols_, false), ly = taps(row, height_, rows_, false);
            double sw = 0;
            sc = sf = 0;
            for (int j = 0; j < ly.count; ++j)
                for (int i = 0; i < lx.count; ++i) {
                    const std::size_t k = point(lx.index[i], ly.index[j]);
                    const double w = lx.weight[i] * ly.weight[j];
                    if (w <= 0 || !has_[k]) continue;
                    sw += w, sc += w * c_[k], sf += w * f_[k];
                }
            if (!(sw > 0)) return false;
            sc /= sw, sf /= sw;
        }
        c = float(std::max(0.0, sc)), f = float(std::clamp(sf, 0.0, 100.0));
        return true;
    }

  private:
    // The lattice points along one axis that a coordinate's value is made of, and their
    // weights (summing to 1).
    struct Taps {
        int index[4] = {0, 0, 0, 0};
        double weight[4] = {0, 0, 0, 0};
        int count = 0;
    };

    int points(int size) const { return (size - 1) / stride_ + 1 + ((size - 1) % stride_ != 0); }
    int lattice_index(int x, int size, int count) const {
        return x == size - 1 ? count - 1 : x / stride_;
    }
    std::size_t index(int col, int row) const {
        return point(lattice_index(col, width_, cols_), lattice_index(row, height_, rows_));
    }
    std::size_t point(int i, int j) const {
        return std::size_t(j) * std::size_t(cols_) + std::size_t(i);
    }

    // Coordinate x's taps: the lattice point itself; or the Catmull-Rom cubic's four points in
    // a cell of the stride's width; or the cell's two ends, linearly.
    Taps taps(int x, int size, int count, bool cubic) const {
        Taps t;
        const int a = x / stride_ * stride_;
        if (x == a || x == size - 1) {
            t.index[0] = lattice_index(x, size, count), t.weight[0] = 1, t.count = 1;
            return t;
        }
        const int b = std::min(a + stride_, size - 1), i0 = a / stride_;
        const double u = double(x - a) / double(b - a);
        const int regular = (size - 1) / stride_;  // the last point on the stride
        if (!cubic || b != a + stride_) {
            t.index[0] = i0, t.index[1] = lattice_index(b, size, count);
            t.weight[0] = 1 - u, t.weight[1] = u, t.count = 2;
            return t;
        }
        const double u2 = u * u, u3 = u2 * u;
        t.index[0] = i0 - 1, t.index[1] = i0, t.index[2] = i0 + 1, t.index[3] = i0 + 2;
        t.weight[0] = 0.5 * (-u3 + 2 * u2 - u);
        t.weight[1] = 0.5 * (3 * u3 - 5 * u2 + 2);
        t.weight[2] = 0.5 * (-3 * u3 + 4 * u2 + u);
        t.weight[3] = 0.5 * (u3 - u2);
        // Past the lattice's ends a point extrapolated along the line through the last two
        // (so that a linear field comes back exactly).
        if (t.index[0] < 0) {
            t.weight[1] += 2 * t.weight[0], t.weight[2] -= t.weight[0];
            t.index[0] = i0, t.weight[0] = 0;
        }
        if (t.index[3] > regular) {
            t.weight[2] += 2 * t.weight[3], t.weight[1] -= t.weight[3];
            t.index[3] = i0 + 1, t.weight[3] = 0;
        }
        t.count = 4;
        return t;
    }

    int width_, height_, stride_, cols_, rows_;
    std::vector<float> c_, f_;
    std::vector<std::uint8_t> has_;
};

}  // namespace terrain::field::detail
