// sweep.png: a small line plot drawn on a map_canvas.hpp Canvas (no plotting library in the
// stack): region count in blue on the left axis, mean region area in red on the right axis,
// against the area ratio on a log axis; axis titles, tick values and the legend in DejaVu Sans
// (none without the font).

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "map_canvas.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/significant.hpp"
#include "terrain/io/write_sweep_plot.hpp"

namespace terrain::io {

namespace {

std::string short_number(double v) {
    return terrain::detail::significant(v, 4);
}

// The smallest 4 * (1, 2, 2.5 or 5 times a power of ten) at least `v`: an axis's top whose
// quarters are round numbers.
double axis_top(double v) {
    const double quarter = v / 4;
    const double magnitude = std::pow(10.0, std::floor(std::log10(quarter)));
    for (const double m : {1.0, 2.0, 2.5, 5.0, 10.0})
        if (m * magnitude >= quarter * (1 - 1e-12)) return 4 * m * magnitude;
    return 40 * magnitude;
}

}  // namespace

void write_sweep_plot(const std::vector<double>& ratios, const std::vector<double>& counts,
                      const std::vector<double>& areas, const std::string& path, bool overwrite) {
    using detail::AlignX;
    using detail::AlignY;
    using detail::Rgba;
    if (ratios.empty() || ratios.size() != counts.size() || ratios.size() != areas.size())
        throw Error("write", "sweep plot: one count and one area per area ratio are needed");
    for (const double r : ratios)
        if (!(r > 0)) throw Error("write", "sweep plot: area ratios must be positive");
    const int W = 900, H = 560, left = 100, right = W - 100, top = 60, bottom = H - 90;
    const int f = 14;
    detail::Canvas c(W, H, {255, 255, 255, 255}, detail::map_font());
    const Rgba black{0, 0, 0, 255}, grey{200, 200, 200, 255}, blue{40, 90, 200, 255},
        red{210, 50, 40, 255};
    const auto [rmin, rmax] = std::minmax_element(ratios.begin(), ratios.end());
    const double l0 = std::log10(*rmin), l1 = std::max(std::log10(*rmax), l0 + 1e-9);
    const double cmax = axis_top(std::max(1.0, *std::max_element(counts.begin(), counts.end())));
    // Areas in km² from 1 km² up, in m² below.
    const double amax_m2 = std::max(1e-300, *std::max_element(areas.begin(), areas.end()));
    const bool km2 = amax_m2 >= 1e6;
    const double unit = km2 ? 1e6 : 1.0;
    const double amax = axis_top(amax_m2 / unit);
    auto X = [&](double r) {
        return left + static_cast<int>((std::log10(r) - l0) / (l1 - l0) * (right - left));
    };
    auto Y = [&](double v, double vmax) {
        return bottom - static_cast<int>(v / vmax * (bottom - top));
    };
    for (int k = 0; k <= 4; ++k) {  // horizontal grid and both axes' tick values
        const int y = bottom - k * (bottom - top) / 4;
        c.fill(left, y, right - left, 1, grey);
        c.text(left - 8, y, short_number(cmax * k / 4), f, blue, AlignX::right, AlignY::middle);
        c.text(right + 8, y, short_number(amax * k / 4), f, red, AlignX::left, AlignY::middle);
    }
    c.fill(left - 1, top, 2, bottom - top + 1, black);
    c.fill(right - 1, top, 2, bottom - top + 1, black);
    c.fill(left - 1, bottom, right - left + 2, 2, black);
    for (const double r : ratios) {
        c.fill(X(r), bottom, 1, 6, black);
        c.text(X(r), bottom + 10, short_number(r), f, black, AlignX::centre, AlignY::top);
    }
    for (std::size_t i = 0; i < ratios.size(); ++i) {
        const double a = areas[i] / unit;
        if (i > 0) {
            c.line(X(ratios[i - 1]), Y(counts[i - 1], cmax), X(ratios[i]), Y(counts[i], cmax), blue,
                   2.5);
            c.line(X(ratios[i - 1]), Y(areas[i - 1] / unit, amax), X(ratios[i]), Y(a, amax), red,
                   2.5);
        }
        c.disc(X(ratios[i]), Y(counts[i], cmax), 4.5, blue);
        c.disc(X(ratios[i]), Y(a, amax), 4.5, red);
    }
    // Axis titles.
    const std::string area_title = std::string("mean region area (") + (km2 ? "km²" : "m²") + ")";
    c.text((left + right) / 2, bottom + 40, "area ratio (% of the surface, log scale)", f + 1,
           black, AlignX::centre, AlignY::top);
    c.text(left - 8, top - 14, "regions", f + 1, blue, AlignX::right, AlignY::bottom);
    c.text(W - 8, top - 14, area_title, f + 1, red, AlignX::right, AlignY::bottom);
    // Legend: a line with its marker and its name for each series.
    const int ly = 22;
    int lx = left + 20;
    for (const auto& [colour, name] : {std::pair<Rgba, std::string>{blue, "region count"},
                                       std::pair<Rgba, std::string>{red, area_title}}) {
        c.line(lx, ly, lx + 30, ly, colour, 2.5);
        c.disc(lx + 15, ly, 4.5, colour);
        lx += 40 + c.text(lx + 40, ly, name, f, black, AlignX::left, AlignY::middle) + 40;
    }

    detail::write_canvas(c, path, overwrite);
}

}  // namespace terrain::io
