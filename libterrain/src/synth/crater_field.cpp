#include "terrain/synth/crater_field.hpp"

#include <cpl_conv.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "terrain/core/body.hpp"
#include "terrain/core/error.hpp"

// Determinism: the surface is built from IEEE-exact arithmetic and sqrt (no fused
// multiply-adds, single-threaded, fixed evaluation order) and our own PRNG. libm (sin, cos,
// asin, exp, pow) only sets up the geometry and the crater sizes; the last-ulp differences
// between libms vanish under the 2 m DN quantisation.
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

namespace terrain::synth {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegree = kPi / 180.0;
// Ejecta reach, in crater radii: the (r/R)^-3 blanket is tapered to zero between 2 R and 3 R
// (the continuous ejecta blanket ends about one radius beyond the rim; Melosh 1989, ch. 6).
constexpr double kReach = 3.0;
constexpr double kTaperStart = 2.0;

// ---------------------------------------------------------------------------------------
// Random numbers: splitmix64 (Steele, Lea & Flood 2014) with a 53-bit uniform double, so that
// the same seed gives the same numbers with any compiler and standard library.

std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

double to_unit(std::uint64_t bits) {  // [0,1)
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

std::uint64_t stream_seed(std::uint64_t seed, Stream stream) {
    return mix64(seed ^ mix64(0x632be59bd9b4e019ULL * static_cast<std::uint64_t>(stream)));
}

// ---------------------------------------------------------------------------------------
// Fractal roughness: octaves of value noise (smoothly interpolated random lattice values)
// whose amplitude falls as wavelength^hurst, a self-affine surface (Turcotte 1997, ch. 7).

double lattice_value(std::uint64_t key, std::int64_t ix, std::int64_t iy) {
    const std::uint64_t h =
        mix64(key ^ mix64(static_cast<std::uint64_t>(ix) * 0x9e3779b97f4a7c15ULL +
                          static_cast<std::uint64_t>(iy)));
    return 2.0 * to_unit(h) - 1.0;  // [-1,1)
}

double fade(double t) {
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}  // C2 quintic

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
    void tabulate(double x0, double x1, double y0, double y1) {
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
                table_[static_cast<std::size_t>(j * nu_ + i)] =
                    lattice_value(key_, u0_ + i, v0_ + j);
    }

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
                                 double y0, double y1) {
    std::vector<Octave> octaves;
    if (amplitude_at_longest <= 0) return octaves;
    Rng rng(seed);
    for (double wavelength = longest; wavelength >= 2.0 * pixel; wavelength *= 0.5) {
        const double angle = rng.uniform(0.0, 2.0 * kPi);
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

double fractal(const std::vector<Octave>& octaves, double x, double y) {
    double z = 0;
    for (const auto& octave : octaves) z += octave(x, y);
    return z;
}

// ---------------------------------------------------------------------------------------
// Geometry of the tile and of the extended grid (the tile plus a margin wide enough for the
// largest crater's ejecta) on which the surface is built.

struct Geometry {
    double radius = kVestaRadius;
    double pixel = 0;   // metres in the projection (x and y)
    double lat_ts = 0;  // latitude of true scale, radians
    double cos_ts = 1;
    double x_left = 0, y_top = 0;  // tile's top-left corner in projected metres
    int margin_x = 0, margin_y = 0;
    int width = 0, height = 0;  // extended grid
    // Projected coordinates of the centre of extended-grid pixel (col,row).
    double x_of(double col) const { return x_left + (col - margin_x + 0.5) * pixel; }
    double y_of(double row) const { return y_top - (row - margin_y + 0.5) * pixel; }
    // Ground metres per projected metre along a parallel at latitude `lat` (radians).
    double east_scale(double lat) const { return std::cos(lat) / cos_ts; }
};

struct Grid {
    int width = 0, height = 0;
    std::vector<double> z;
    double& at(int col, int row) {
        return z[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
                 static_cast<std::size_t>(col)];
    }
    double at(int col, int row) const {
        return z[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
                 static_cast<std::size_t>(col)];
    }
    // Bilinear at a continuous position (pixel centres at +0.5), clamped to the grid.
    double sample(double col, double row) const {
        const double u = std::clamp(col - 0.5, 0.0, double(width - 1));
        const double v = std::clamp(row - 0.5, 0.0, double(height - 1));
        const int i = std::min(static_cast<int>(u), width - 2);
        const int j = std::min(static_cast<int>(v), height - 2);
        const double fu = u - i, fv = v - j;
        const double a = at(i, j) + fu * (at(i + 1, j) - at(i, j));
        const double b = at(i, j + 1) + fu * (at(i + 1, j + 1) - at(i, j + 1));
        return a + fv * (b - a);
    }
};

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

// Fraction of the relief a crater of diameter `d` has lost after `age` (fraction of the
// surface age): topographic diffusion degrades a crater on a time scale proportional to D^2
// (Soderblom 1970; Fassett & Thomson 2014), so 1 - exp(-ln2 * age * (D_half / D)^2).
double degradation(double d, double age, double d_half) {
    if (d_half <= 0) return 0;
    const double r = d_half / d;
    return 1.0 - std::exp(-std::numbers::ln2 * age * r * r);
}

// ---------------------------------------------------------------------------------------
// Craters

double smoothstep(double e0, double e1, double x) {
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// Polynomial smooth minimum (Quilez): min(a,b) rounded over |a-b| < k, by k/4 where a = b.
double smooth_min(double a, double b, double k) {
    const double h = std::max(k - std::abs(a - b), 0.0) / k;
    return std::min(a, b) - h * h * k * 0.25;
}

struct Shape {
    double depth_ratio, rim_ratio;
};

// Adds one simple crater to the surface. Heights relative to the pre-impact surface, with
// s = r / R (R the rim-crest radius):
//  - bowl: a paraboloid, rim-to-floor depth H = 0.2 D for fresh simple craters (Pike 1977,
//    d = 0.196 D for lunar simple craters; Vincent et al. 2014 find 0.15-0.2 on Vesta; every
//    crater of this tile is simple, Vesta's simple-to-complex transition being near 30 km);
//  - rim crest at height h = 0.04 D (Pike 1977: h = 0.036 D^1.014), rounded over a width
//    growing with degradation;
//  - ejecta blanket beyond the rim, thickness h (r/R)^-3 (McGetchin, Settle & Head 1973:
//    t = 0.14 R^0.74 (r/R)^-3.0), tapered to zero between 2 R and 3 R.
// Inside the rim the crater replaces the old surface (a plane fitted on the old rim) rather than
// adding to it, so that young craters cut cleanly into old ones; ejecta add to what is there.
// Degradation q in [0,1) scales the depth by (1-q) and the rim by (1-q)^1.5 (rims and ejecta
// soften first) and widens the rounding of the rim crest.
void add_crater(Grid& grid, const Geometry& geo, const Crater& c, const Shape& shape) {
    const double q = c.degradation;
    const double radius = 0.5 * c.diameter;
    const double depth = shape.depth_ratio * c.diameter * (1.0 - q);
    const double rim = shape.rim_ratio * c.diameter * std::pow(1.0 - q, 1.5);
    const double rounding = (0.04 + 0.4 * q) * (2.0 * depth + 3.0 * rim);  // smooth_min width
    if (rounding <= 0) return;
    // Both branches meet at rim + rounding/4 at s = 1, so that the rounded crest sits at `rim`
    // and the floor (s = 0) at rim - depth.
    const double lift = 0.25 * rounding;
    const double floor_z = rim - depth;

    const double ce = c.col + geo.margin_x, re = c.row + geo.margin_y;
    const double lat = geo.y_of(re - 0.5) / geo.radius;
    const double kx = geo.east_scale(lat) * geo.pixel;  // ground metres per column
    const double ky = geo.pixel;                        // ground metres per row

    // The old surface's plane from eight points on the rim circle.
    static constexpr double h2 = 0.70710678118654752440;
    static constexpr std::array<std::array<double, 2>, 8> dirs{
        {{1, 0}, {h2, h2}, {0, 1}, {-h2, h2}, {-1, 0}, {-h2, -h2}, {0, -1}, {h2, -h2}}};
    double mean = 0, grad_e = 0, grad_n = 0;
    for (const auto& d : dirs) {
        const double z = grid.sample(ce + radius * d[0] / kx, re - radius * d[1] / ky);
        mean += z;
        grad_e += z * d[0];
        grad_n += z * d[1];
    }
    mean /= 8.0;
    grad_e /= 4.0 * radius;
    grad_n /= 4.0 * radius;

    const double reach = kReach * radius;
    const int r0 = std::max(0, static_cast<int>(std::floor(re - reach / ky - 0.5)));
    const int r1 = std::min(grid.height - 1, static_cast<int>(std::ceil(re + reach / ky - 0.5)));
    const int c0 = std::max(0, static_cast<int>(std::floor(ce - reach / kx - 0.5)));
    const int c1 = std::min(grid.width - 1, static_cast<int>(std::ceil(ce + reach / kx - 0.5)));
    const double inv_r = 1.0 / radius;
    const double erase = 1.0 - q;  // degraded craters let the old surface show through
    for (int row = r0; row <= r1; ++row) {
        const double dn = (re - (row + 0.5)) * ky;
        const double across = reach * reach - dn * dn;
        if (across <= 0) continue;
        // Columns within the reach on this row (one spare column each side; s decides).
        const double half = std::sqrt(across) / kx + 1.0;
        const int first = std::max(c0, static_cast<int>(std::floor(ce - half - 0.5)));
        const int last = std::min(c1, static_cast<int>(std::ceil(ce + half - 0.5)));
        for (int col = first; col <= last; ++col) {
            const double de = (col + 0.5 - ce) * kx;
            const double s = std::sqrt(de * de + dn * dn) * inv_r;
            if (s >= kReach) continue;
            // Away from the rim one branch is lower by more than the rounding width, where
            // smooth_min is exactly min: s <= 0.5 is all bowl, s >= 1.6 all ejecta.
            const double bowl = floor_z + (depth + lift) * s * s;
            double profile = bowl;
            if (s > 0.5) {
                const double t = s;
                double ejecta = (rim + lift) / (t * t * t);
                if (s > kTaperStart) ejecta *= 1.0 - smoothstep(kTaperStart, kReach, s);
                profile = s < 1.6 ? smooth_min(bowl, ejecta, rounding) : ejecta;
            }
            double& z = grid.at(col, row);
            if (s < 1.0) {
                const double plane = mean + grad_e * de + grad_n * dn;
                const double w = erase * (s > 0.7 ? 1.0 - smoothstep(0.7, 1.0, s) : 1.0);
                z += profile + w * (plane - z);
            } else {
                z += profile;
            }
        }
    }
}

}  // namespace

std::string vesta_equirectangular_wkt(double center_lon, double standard_parallel) {
    // Named as GDAL's PDS driver names the CRS of an EQUIRECTANGULAR label for TARGET_NAME =
    // VESTA, so that the tile and its PDS3 files carry the same CRS.
    OGRSpatialReference srs;
    srs.SetEquirectangular2(0.0, center_lon, standard_parallel, 0.0, 0.0);
    srs.SetProjCS("EQUIRECTANGULAR VESTA");
    srs.SetGeogCS("GCS_VESTA", "D_VESTA", "VESTA_localRadius", kVestaRadius, 0.0,
                  "Reference_Meridian", 0.0);
    char* wkt = nullptr;
    const char* options[] = {"FORMAT=WKT2_2019", nullptr};
    std::string text;
    if (srs.exportToWkt(&wkt, options) == OGRERR_NONE && wkt) text = wkt;
    CPLFree(wkt);
    if (text.empty())
        throw Error("synth", "cannot build the Vesta equirectangular CRS (GDAL/PROJ)");
    return text;
}

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
    dem.body = body_from_crs(dem.crs_wkt);
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
