#include "tile_grid.hpp"

#include <numbers>
#include <string>

#include "crater_shape.hpp"
#include "terrain/core/error.hpp"

namespace terrain::synth {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

void check(bool ok, const std::string& message) {
    if (!ok) throw Error("synth", message);
}

}  // namespace

Geometry make_geometry(const VestaTileOptions& o) {
    Geometry g;
    g.pixel = kDegree * g.radius / o.pixels_per_degree;
    g.lat_ts = o.standard_parallel.value_or(o.center_lat) * kDegree;
    g.cos_ts = std::cos(g.lat_ts);
    // Central meridian through the tile centre; rows on the 1/ppd-degree latitude grid.
    g.x_left = -0.5 * o.width * g.pixel;
    g.y_top = std::round((g.radius * o.center_lat * kDegree + 0.5 * o.height * g.pixel) / g.pixel) *
              g.pixel;

    // The margin follows the random population only (so that adding craters by hand does not
    // move it); with no population, it covers the added craters.
    double largest = o.max_diameter;
    if (o.crater_density <= 0) {
        largest = 0;
        for (const auto& c : o.craters) largest = std::max(largest, c.diameter);
    }
    const double reach = kReach * 0.5 * largest;
    g.margin_y = static_cast<int>(std::ceil(reach / g.pixel)) + 1;
    const double lat_top = (g.y_top + g.margin_y * g.pixel) / g.radius;
    const double lat_bottom = (g.y_top - (o.height + g.margin_y) * g.pixel) / g.radius;
    const double worst = std::max(std::abs(lat_top), std::abs(lat_bottom));
    check(worst < 85 * kDegree,
          "the tile and its crater margin reach latitude " +
              std::to_string(static_cast<int>(worst / kDegree)) +
              " degrees; move the tile equatorward or make it smaller (an equirectangular tile "
              "must stay within +-85 degrees)");
    g.margin_x = static_cast<int>(std::ceil(reach / (g.pixel * g.east_scale(worst)))) + 1;
    const long long cells = (static_cast<long long>(o.width) + 2LL * g.margin_x) *
                            (static_cast<long long>(o.height) + 2LL * g.margin_y);
    check(cells <= 200'000'000LL, "the tile with its crater margin would hold " +
                                      std::to_string(cells) +
                                      " pixels; make the tile or max_diameter smaller");
    g.width = o.width + 2 * g.margin_x;
    g.height = o.height + 2 * g.margin_y;
    return g;
}

}  // namespace terrain::synth
