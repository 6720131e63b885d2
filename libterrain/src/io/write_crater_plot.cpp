// craters.png (write_craters.hpp): two log-log panels drawn on a map_canvas.hpp Canvas, as
// sweep.png is: depth / diameter against the diameter, and the cumulative size-frequency
// distribution, the planetary scientist's first look at a crater count.

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "map_canvas.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/significant.hpp"
#include "terrain/io/write_craters.hpp"

namespace terrain::io {
namespace {

using detail::AlignX;
using detail::AlignY;
using detail::Rgba;

const Rgba kBlack{0, 0, 0, 255}, kGrey{210, 210, 210, 255}, kBlue{40, 90, 200, 255};
constexpr int kFont = 13;

// A log-log panel: decades [x0, x1] and [y0, y1] of log10 values, drawn in the box.
struct Panel {
    int left, right, top, bottom;
    double x0, x1, y0, y1;
    double X(double v) const { return left + (std::log10(v) - x0) / (x1 - x0) * (right - left); }
    double Y(double v) const { return bottom - (std::log10(v) - y0) / (y1 - y0) * (bottom - top); }
    bool holds(double x, double y) const {
        return x > 0 && y > 0 && std::log10(x) >= x0 && std::log10(x) <= x1 &&
               std::log10(y) >= y0 && std::log10(y) <= y1;
    }
};

std::string decade(int e) {
    return terrain::detail::significant(std::pow(10.0, e), 3);
}

void axes(detail::Canvas& c, const Panel& p, const std::string& x_title,
          const std::string& y_title) {
    for (int e = int(p.x0); e <= int(p.x1); ++e) {
        const int x = int(p.X(std::pow(10.0, e)));
        c.fill(x, p.top, 1, p.bottom - p.top, kGrey);
        c.text(x, p.bottom + 8, decade(e), kFont, kBlack, AlignX::centre, AlignY::top);
    }
    for (int e = int(p.y0); e <= int(p.y1); ++e) {
        const int y = int(p.Y(std::pow(10.0, e)));
        c.fill(p.left, y, p.right - p.left, 1, kGrey);
        c.text(p.left - 8, y, decade(e), kFont, kBlack, AlignX::right, AlignY::middle);
    }
    c.fill(p.left - 1, p.top, 2, p.bottom - p.top + 1, kBlack);
    c.fill(p.left - 1, p.bottom, p.right - p.left + 2, 2, kBlack);
    c.text((p.left + p.right) / 2, p.bottom + 32, x_title, kFont + 1, kBlack, AlignX::centre,
           AlignY::top);
    c.text(p.left, p.top - 12, y_title, kFont + 1, kBlack, AlignX::left, AlignY::bottom);
}

}  // namespace

void write_craters_plot(const segment::CraterTable& table, double area_m2, const std::string& path,
                        bool overwrite) {
    if (!(area_m2 > 0) || !std::isfinite(area_m2))
        throw Error("write", "craters.png: the counted area must be positive");
    const int W = 1000, H = 500;
    detail::Canvas c(W, H, {255, 255, 255, 255}, detail::map_font());
    std::vector<double> d_km;
    for (const auto& k : table.craters) d_km.push_back(k.diameter_m / 1000);
    std::sort(d_km.begin(), d_km.end(), std::greater<>());
    const double dmin = d_km.empty() ? 1 : d_km.back(), dmax = d_km.empty() ? 10 : d_km.front();
    const double x0 = std::floor(std::log10(dmin)),
                 x1 = std::max(x0 + 1, std::ceil(std::log10(dmax)));
    const double area_km2 = area_m2 / 1e6;
    const double n = double(std::max<std::size_t>(d_km.size(), 1));
    const Panel dd{80, 470, 60, 410, x0, x1, -3, 0};
    const Panel sfd{
        590,
        980,
        60,
        410,
        x0,
        x1,
        std::floor(std::log10(1 / area_km2)),
        std::max(std::floor(std::log10(1 / area_km2)) + 1, std::ceil(std::log10(n / area_km2)))};
    axes(c, dd, "diameter (km)", "depth / diameter");
    axes(c, sfd, "diameter D (km)", "craters at least D across, per km²");
    for (const auto& k : table.craters) {
        const double D = k.diameter_m / 1000, ratio = k.depth_m / k.diameter_m;
        if (dd.holds(D, ratio)) c.disc(dd.X(D), dd.Y(ratio), 2.5, kBlue);
    }
    // The cumulative count: the i-th largest crater has i + 1 at least its size.
    for (std::size_t i = 0; i < d_km.size(); ++i) {
        const double density = double(i + 1) / area_km2;
        if (sfd.holds(d_km[i], density)) c.disc(sfd.X(d_km[i]), sfd.Y(density), 2.5, kBlue);
    }
    c.text(W / 2, 12,
           std::to_string(table.craters.size()) + " craters on " +
               (area_km2 >= 1 ? std::to_string(std::llround(area_km2))
                              : terrain::detail::significant(area_km2, 4)) +
               " km²",
           kFont + 1, kBlack, AlignX::centre, AlignY::top);
    detail::write_canvas(c, path, overwrite);
}

}  // namespace terrain::io
