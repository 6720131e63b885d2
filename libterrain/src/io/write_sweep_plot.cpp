// sweep.png: a small line plot drawn by hand (no plotting library in the stack): region count
// in blue on the left axis, mean region area in red on the right axis, against the area ratio
// on a log axis; tick values in a built-in 3x5 digit font.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "image_module.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/write_sweep_plot.hpp"

namespace terrain::io {

namespace {

using Rgb = std::array<std::uint8_t, 3>;

// 3x5 glyphs for digits, '.', 'e', '+', '-': one row per 3 bits, top to bottom.
std::array<int, 5> glyph(char c) {
    switch (c) {
        case '0':
            return {7, 5, 5, 5, 7};
        case '1':
            return {2, 6, 2, 2, 7};
        case '2':
            return {7, 1, 7, 4, 7};
        case '3':
            return {7, 1, 7, 1, 7};
        case '4':
            return {5, 5, 7, 1, 1};
        case '5':
            return {7, 4, 7, 1, 7};
        case '6':
            return {7, 4, 7, 5, 7};
        case '7':
            return {7, 1, 1, 1, 1};
        case '8':
            return {7, 5, 7, 5, 7};
        case '9':
            return {7, 5, 7, 1, 7};
        case '.':
            return {0, 0, 0, 0, 2};
        case 'e':
            return {0, 7, 7, 4, 7};
        case '+':
            return {0, 2, 7, 2, 0};
        case '-':
            return {0, 0, 7, 0, 0};
        default:
            return {0, 0, 0, 0, 0};
    }
}

class Canvas {
  public:
    Canvas(int w, int h) : w_(w), h_(h), px_(static_cast<std::size_t>(w * h) * 3, 255) {}
    void dot(int x, int y, Rgb c, int r = 0) {
        for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx) {
                const int xx = x + dx, yy = y + dy;
                if (xx < 0 || yy < 0 || xx >= w_ || yy >= h_) continue;
                const auto i = static_cast<std::size_t>(yy * w_ + xx) * 3;
                px_[i] = c[0], px_[i + 1] = c[1], px_[i + 2] = c[2];
            }
    }
    void line(int x0, int y0, int x1, int y1, Rgb c, int r = 0) {
        const int n = std::max(std::abs(x1 - x0), std::abs(y1 - y0));
        for (int i = 0; i <= n; ++i)
            dot(x0 + (n ? (x1 - x0) * i / n : 0), y0 + (n ? (y1 - y0) * i / n : 0), c, r);
    }
    void text(int x, int y, const std::string& s, Rgb c, int scale = 2) {
        for (const char ch : s) {
            const auto g = glyph(ch);
            for (int row = 0; row < 5; ++row)
                for (int col = 0; col < 3; ++col)
                    if (g[static_cast<std::size_t>(row)] & (4 >> col))
                        for (int a = 0; a < scale; ++a)
                            for (int b = 0; b < scale; ++b)
                                dot(x + col * scale + a, y + row * scale + b, c);
            x += 4 * scale;
        }
    }
    const std::uint8_t* data() const { return px_.data(); }

  private:
    int w_, h_;
    std::vector<std::uint8_t> px_;
};

std::string short_number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
}

}  // namespace

void write_sweep_plot(const std::vector<double>& ratios, const std::vector<double>& counts,
                      const std::vector<double>& areas, const std::string& path, bool overwrite) {
    if (ratios.empty() || ratios.size() != counts.size() || ratios.size() != areas.size())
        throw Error("write", "sweep plot: one count and one area per area ratio are needed");
    for (const double r : ratios)
        if (!(r > 0)) throw Error("write", "sweep plot: area ratios must be positive");
    const int W = 900, H = 540, left = 90, right = W - 90, top = 40, bottom = H - 70;
    Canvas c(W, H);
    const Rgb black{0, 0, 0}, grey{200, 200, 200}, blue{40, 90, 200}, red{210, 50, 40};
    const auto [rmin, rmax] = std::minmax_element(ratios.begin(), ratios.end());
    const double l0 = std::log10(*rmin), l1 = std::max(std::log10(*rmax), l0 + 1e-9);
    const double cmax = std::max(1.0, *std::max_element(counts.begin(), counts.end()));
    const double amax = std::max(1e-300, *std::max_element(areas.begin(), areas.end()));
    auto X = [&](double r) {
        return left + static_cast<int>((std::log10(r) - l0) / (l1 - l0) * (right - left));
    };
    auto Y = [&](double v, double vmax) {
        return bottom - static_cast<int>(v / vmax * (bottom - top));
    };
    for (int k = 0; k <= 4; ++k) {  // horizontal grid and both axes' tick values
        const int y = bottom - k * (bottom - top) / 4;
        c.line(left, y, right, y, grey);
        c.text(8, y - 5, short_number(cmax * k / 4), blue);
        c.text(right + 8, y - 5, short_number(amax * k / 4), red);
    }
    c.line(left, top, left, bottom, black, 1);
    c.line(right, top, right, bottom, black, 1);
    c.line(left, bottom, right, bottom, black, 1);
    for (const double r : ratios) {
        c.line(X(r), bottom, X(r), bottom + 6, black);
        const std::string label = short_number(r);
        c.text(X(r) - static_cast<int>(label.size()) * 4, bottom + 14, label, black);
    }
    for (std::size_t i = 0; i < ratios.size(); ++i) {
        if (i > 0) {
            c.line(X(ratios[i - 1]), Y(counts[i - 1], cmax), X(ratios[i]), Y(counts[i], cmax), blue,
                   1);
            c.line(X(ratios[i - 1]), Y(areas[i - 1], amax), X(ratios[i]), Y(areas[i], amax), red,
                   1);
        }
        c.dot(X(ratios[i]), Y(counts[i], cmax), blue, 4);
        c.dot(X(ratios[i]), Y(areas[i], amax), red, 4);
    }
    // Legend: blue square = region count, red = mean area (m^2); x axis: area ratio, percent.
    c.dot(left + 20, 18, blue, 6);
    c.dot(left + 200, 18, red, 6);

    AtomicOutput output(path, overwrite);
    detail::write_image(output.temp_path(), path, W, H, 3, c.data());
    output.commit();
}

}  // namespace terrain::io
