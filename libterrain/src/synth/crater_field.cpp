// The synthetic Vesta tile: the options checked, the random crater population, and the surface
// built from the regional relief (tilt, undulation, fractal roughness) and the craters, oldest
// first, then quantised to the HAMO DN grid.
#include "terrain/synth/crater_field.hpp"

#include "deterministic.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "crater_shape.hpp"
#include "fractal_noise.hpp"
#include "random.hpp"
#include "terrain/core/body.hpp"
#include "terrain/core/error.hpp"
#include "terrain/synth/vesta_crs.hpp"
#include "tile_grid.hpp"

namespace terrain::synth {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegree = kPi / 180.0;

void check(bool ok, const std::string& message) {
    if (!ok) throw Error("synth", message);
}

void validate(const VestaTileOptions& o) {
    const auto finite = [](double v) { return std::isfinite(v); };
    check(o.width >= 2 && o.height >= 2 && o.width <= 16384 && o.height <= 16384,
          "the tile must be 2 to 16384 pixels wide and high, not " + std::to_string(o.width) + "x" +
              std::to_string(o.height));
    check(finite(o.center_lon) && finite(o.center_lat) && std::abs(o.center_lat) < 80,
          "the tile centre must have a finite longitude and a latitude within +-80 degrees");
    check(finite(o.pixels_per_degree) && o.pixels_per_degree >= 1 && o.pixels_per_degree <= 1e4,
          "pixels_per_degree must be between 1 and 10000 (HAMO: 64)");
    check(!o.standard_parallel ||
              (finite(*o.standard_parallel) && std::abs(*o.standard_parallel) <= 80),
          "the standard parallel must lie within +-80 degrees");
    check(finite(o.crater_density) && o.crater_density >= 0,
          "crater_density must be a number of craters per km^2, 0 or more");
    check(finite(o.size_exponent) && o.size_exponent > 0 && o.size_exponent <= 6,
          "size_exponent must be in (0, 6] (about 2 for a cratered surface)");
    check(finite(o.min_diameter) && finite(o.max_diameter) && o.min_diameter > 0 &&
              o.max_diameter >= o.min_diameter && o.max_diameter <= 200000,
          "crater diameters need 0 < min_diameter <= max_diameter <= 200 km");
    check(finite(o.depth_ratio) && o.depth_ratio > 0 && o.depth_ratio <= 1 && finite(o.rim_ratio) &&
              o.rim_ratio >= 0 && o.rim_ratio < o.depth_ratio,
          "crater shape needs 0 < depth_ratio <= 1 and 0 <= rim_ratio < depth_ratio (fresh "
          "simple craters: 0.2 and 0.04)");
    check(finite(o.degradation_diameter) && o.degradation_diameter >= 0,
          "degradation_diameter must be 0 (no degradation) or more metres");
    check(finite(o.base_height) && std::abs(o.base_height) <= 40000 && finite(o.regional_slope) &&
              std::abs(o.regional_slope) <= 1 && finite(o.undulation_amplitude) &&
              o.undulation_amplitude >= 0 && o.undulation_amplitude <= 20000 &&
              finite(o.roughness_amplitude) && o.roughness_amplitude >= 0 &&
              o.roughness_amplitude <= 2000 && finite(o.hurst) && o.hurst >= 0 && o.hurst <= 1.5,
          "relief out of range: |base_height| <= 40 km, |regional_slope| <= 1, "
          "undulation_amplitude 0-20 km, roughness_amplitude 0-2 km, hurst 0-1.5");
    for (const auto& c : o.craters)
        check(finite(c.col) && finite(c.row) && finite(c.diameter) && c.diameter > 0 &&
                  c.diameter <= 200000 && finite(c.degradation) && c.degradation >= 0 &&
                  c.degradation < 1,
              "each added crater needs a finite centre, a diameter in (0, 200 km] and a "
              "degradation in [0, 1)");
}

}  // namespace

std::vector<Crater> vesta_crater_population(const VestaTileOptions& options) {
    validate(options);
    const Geometry geo = make_geometry(options);
    std::vector<Crater> craters;
    if (options.crater_density <= 0) return craters;

    // Ground area of the extended grid: R^2 * dlon * (sin lat_top - sin lat_bottom).
    const double lat_top = (geo.y_top + geo.margin_y * geo.pixel) / geo.radius;
    const double lat_bottom = lat_top - geo.height * geo.pixel / geo.radius;
    const double dlon = geo.width * geo.pixel / (geo.radius * geo.cos_ts);
    const double sin_top = std::sin(lat_top), sin_bottom = std::sin(lat_bottom);
    const double area_km2 = geo.radius * geo.radius * dlon * (sin_top - sin_bottom) * 1e-6;
    const double b = options.size_exponent;
    const double dmin_km = options.min_diameter * 1e-3, dmax_km = options.max_diameter * 1e-3;
    const double expected =
        options.crater_density * (std::pow(dmin_km, -b) - std::pow(dmax_km, -b)) * area_km2;
    check(expected <= 5e6, "the crater density would put " +
                               std::to_string(static_cast<long long>(expected)) +
                               " craters on the tile; lower crater_density or raise min_diameter");
    const auto count = static_cast<std::size_t>(std::llround(expected));

    // Sizes by inversion of the truncated power law N(>=D) ~ D^-b on [Dmin, Dmax]; positions
    // uniform over the sphere's area (uniform in sin(latitude)); formation times uniform
    // (constant impact flux).
    Rng rng(stream_seed(options.seed, kPopulation));
    const double tail = std::pow(options.min_diameter / options.max_diameter, b);
    craters.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
        Crater c;
        c.col = rng.uniform() * geo.width - geo.margin_x;
        const double lat = std::asin(sin_bottom + rng.uniform() * (sin_top - sin_bottom));
        c.row = (geo.y_top - geo.radius * lat) / geo.pixel;
        c.diameter = options.min_diameter * std::pow(1.0 - rng.uniform() * (1.0 - tail), -1.0 / b);
        c.age = 1.0 - rng.uniform();  // (0,1]
        c.degradation = degradation(c.diameter, c.age, options.degradation_diameter);
        craters.push_back(c);
    }
    // Oldest first; stable, so equal ages keep their drawing order on every platform.
    std::stable_sort(craters.begin(), craters.end(),
                     [](const Crater& a, const Crater& b2) { return a.age > b2.age; });
    return craters;
}

Dem generate_vesta_tile(const VestaTileOptions& options, const ProgressFn& progress) {
    validate(options);
    const Geometry geo = make_geometry(options);
    report_progress(progress, 0.0, "synth");

    // Regional relief: tilt, undulation, roughness.
    Rng relief(stream_seed(options.seed, kRelief));
    const double tilt_azimuth = relief.uniform(0.0, 2.0 * kPi);
    const double tilt_x = options.regional_slope * std::cos(tilt_azimuth);
    const double tilt_y = options.regional_slope * std::sin(tilt_azimuth);
    // Undulation: plane waves with a red spectrum (longer waves higher), evaluated separably,
    // cos(a + b) = cos a cos b - sin a sin b with a along rows and b along columns.
    struct Wave {
        std::vector<double> cos_x, sin_x, cos_y, sin_y;
        double amplitude = 0;
    };
    std::array<Wave, 4> waves;
    double total = 0;
    for (auto& w : waves) {
        const double wavelength = relief.uniform(20000.0, 80000.0);
        const double direction = relief.uniform(0.0, 2.0 * kPi);
        const double phase = relief.uniform(0.0, 2.0 * kPi);
        const double kx = 2.0 * kPi / wavelength * std::cos(direction);
        const double ky = 2.0 * kPi / wavelength * std::sin(direction);
        for (int col = 0; col < geo.width; ++col) {
            w.cos_x.push_back(std::cos(kx * geo.x_of(col)));
            w.sin_x.push_back(std::sin(kx * geo.x_of(col)));
        }
        for (int row = 0; row < geo.height; ++row) {
            w.cos_y.push_back(std::cos(ky * geo.y_of(row) + phase));
            w.sin_y.push_back(std::sin(ky * geo.y_of(row) + phase));
        }
        w.amplitude = wavelength;
        total += wavelength;
    }
    for (auto& w : waves) w.amplitude *= options.undulation_amplitude / total;
    constexpr double kLongest = 5000.0;
    const double x0 = geo.x_of(0), x1 = geo.x_of(geo.width - 1);
    const double y0 = geo.y_of(geo.height - 1), y1 = geo.y_of(0);
    const auto roughness =
        make_octaves(stream_seed(options.seed, kRoughness), options.roughness_amplitude, kLongest,
                     kLongest, options.hurst, geo.pixel, x0, x1, y0, y1);
    // Regolith texture over everything, young craters included: the short wavelengths again.
    const auto regolith =
        make_octaves(stream_seed(options.seed, kRegolith), 0.35 * options.roughness_amplitude,
                     kLongest, 700.0, options.hurst, geo.pixel, x0, x1, y0, y1);

    Grid grid;
    grid.width = geo.width;
    grid.height = geo.height;
    grid.z.assign(static_cast<std::size_t>(geo.width) * static_cast<std::size_t>(geo.height), 0);
    const double y_centre = geo.y_top - 0.5 * options.height * geo.pixel;  // x_centre is 0
    for (int row = 0; row < geo.height; ++row) {
        const double y = geo.y_of(row);
        for (int col = 0; col < geo.width; ++col) {
            const double x = geo.x_of(col);
            double z = options.base_height + tilt_x * x + tilt_y * (y - y_centre);
            for (const auto& w : waves)
                z += w.amplitude * (w.cos_x[col] * w.cos_y[row] - w.sin_x[col] * w.sin_y[row]);
            z += fractal(roughness, x, y);
            grid.at(col, row) = z;
        }
        if ((row & 127) == 0) report_progress(progress, 0.3 * row / geo.height, "synth");
    }

    // Craters, oldest first, then the caller's.
    const Shape shape{options.depth_ratio, options.rim_ratio};
    const auto population = vesta_crater_population(options);
    const std::size_t n = population.size() + options.craters.size();
    for (std::size_t i = 0; i < n; ++i) {
        add_crater(grid, geo,
                   i < population.size() ? population[i] : options.craters[i - population.size()],
                   shape);
        if ((i & 255) == 0) report_progress(progress, 0.3 + 0.6 * double(i) / double(n), "synth");
    }

    // The tile: regolith texture, then quantisation to the HAMO DN grid.
    Dem dem;
    dem.width = options.width;
    dem.height = options.height;
    dem.transform = {geo.x_left, geo.pixel, 0.0, geo.y_top, 0.0, -geo.pixel};
    dem.has_transform = true;
    const double lon0 = options.center_lon - 360.0 * std::floor(options.center_lon / 360.0);
    dem.crs_wkt = vesta_equirectangular_wkt(lon0, geo.lat_ts / kDegree);
    dem.body = Body{"Vesta", kVestaRadius, 0.0, true};  // what geo reads from that CRS
    dem.elevation = ElevationKind::radius;
    dem.source = "synthetic Vesta tile (seed " + std::to_string(options.seed) + ")";
    dem.values.resize(static_cast<std::size_t>(dem.width) * static_cast<std::size_t>(dem.height));
    for (int row = 0; row < dem.height; ++row) {
        const int re = row + geo.margin_y;
        const double y = geo.y_of(re);
        for (int col = 0; col < dem.width; ++col) {
            const int ce = col + geo.margin_x;
            double z = grid.at(ce, re);
            z += fractal(regolith, geo.x_of(ce), y);
            // Heights above the 255 km sphere, which is also the DN offset.
            const double dn = std::clamp(std::round(z / kHamoScalingFactor), -32767.0, 32767.0);
            dem.values[dem.index(col, row)] = kHamoOffset + kHamoScalingFactor * dn;
        }
    }
    report_progress(progress, 1.0, "synth");
    return dem;
}

}  // namespace terrain::synth
