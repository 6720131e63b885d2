#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <numbers>

#include "support/test_support.hpp"
#include "terrain/core/body.hpp"
#include "terrain/core/error.hpp"
#include "terrain/geo/body.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/synth/crater_field.hpp"

using terrain::synth::Crater;
using terrain::synth::generate_vesta_tile;
using terrain::synth::VestaTileOptions;

namespace {

VestaTileOptions small_tile(int size = 128) {
    VestaTileOptions o;
    o.width = o.height = size;
    return o;
}

// A flat, smooth tile with one crater at the centre of pixel (64,64) of a 128x128 tile.
VestaTileOptions single_crater(double diameter, double degradation = 0) {
    VestaTileOptions o = small_tile();
    o.crater_density = 0;
    o.regional_slope = 0;
    o.undulation_amplitude = 0;
    o.roughness_amplitude = 0;
    o.craters.push_back(Crater{64.5, 64.5, diameter, degradation, 0});
    return o;
}

double height(const terrain::Dem& dem, int col, int row) {
    return dem.at(col, row) - terrain::synth::kVestaRadius;
}

double max_height(const terrain::Dem& dem) {
    double hi = -1e30;
    for (double v : dem.values) hi = std::max(hi, v - terrain::synth::kVestaRadius);
    return hi;
}

}  // namespace

TEST_CASE("the same options give the same bytes, another seed another surface", "[synth]") {
    const auto a = generate_vesta_tile(small_tile());
    const auto b = generate_vesta_tile(small_tile());
    REQUIRE(a.values.size() == 128u * 128u);
    CHECK(std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(double)) == 0);
    CHECK(a.transform == b.transform);
    CHECK(a.crs_wkt == b.crs_wkt);

    auto other = small_tile();
    other.seed += 1;
    const auto c = generate_vesta_tile(other);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.values.size(); ++i) differ += a.values[i] != c.values[i];
    CHECK(differ > a.values.size() / 2);
    CHECK(a.transform == c.transform);  // the seed changes the surface, not the grid
}

TEST_CASE("a tile is a Vesta radius DEM on the HAMO grid", "[synth]") {
    const auto dem = generate_vesta_tile(small_tile());
    CHECK(dem.width == 128);
    CHECK(dem.height == 128);
    CHECK(dem.elevation == terrain::ElevationKind::radius);
    CHECK(dem.body.name == "Vesta");
    CHECK(dem.body.semi_major_axis == 255000);
    CHECK(dem.body.flattening == 0);
    const auto read_body = terrain::geo::body_from_crs(dem.crs_wkt);
    CHECK(read_body.name == "Vesta");
    CHECK(dem.body.name == read_body.name);
    CHECK(dem.body.semi_major_axis == read_body.semi_major_axis);
    CHECK(dem.body.flattening == read_body.flattening);
    CHECK(dem.body.has_crs == read_body.has_crs);
    REQUIRE(dem.has_transform);
    // 64 pixels per degree on the 255 km sphere.
    CHECK(dem.transform[1] == Approx(255000.0 * std::numbers::pi / 180.0 / 64.0).epsilon(1e-12));
    CHECK(dem.transform[5] == -dem.transform[1]);
    CHECK(dem.transform[2] == 0);
    CHECK(dem.transform[4] == 0);
    // Centred on the default tile centre (-30 degrees): y = R * latitude.
    const auto centre = dem.map_xy(64, 64);
    CHECK(centre[0] == Approx(0).margin(1e-6));
    CHECK(centre[1] / 255000.0 * 180.0 / std::numbers::pi == Approx(-30.0).margin(1.0 / 64));

    double lo = 1e30, hi = -1e30;
    for (double v : dem.values) {
        REQUIRE(std::isfinite(v));
        // On the DN grid: radius = DN * 2 + 255000 with DN an int16.
        const double dn = (v - 255000.0) / 2.0;
        REQUIRE(dn == std::round(dn));
        REQUIRE(std::abs(dn) <= 32767);
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    CHECK(lo > 255000.0 - 25000.0);
    CHECK(hi < 255000.0 + 25000.0);
    CHECK(hi - lo > 100.0);  // relief, not a flat plane
}

TEST_CASE("a fresh crater has the simple-crater shape", "[synth]") {
    const double d = 3000.0;  // 43 pixels across, radius 1500 m
    const auto dem = generate_vesta_tile(single_crater(d));
    const double pixel = dem.transform[1];
    const double floor = height(dem, 64, 64);
    const double rim = max_height(dem);
    // Rim-to-floor depth 0.2 D and rim 0.04 D above the surroundings (Pike 1977), floor
    // 0.16 D below them; within the DN step and the pixel sampling of the rim crest.
    CHECK(rim - floor == Approx(0.2 * d).epsilon(0.03));
    CHECK(rim == Approx(0.04 * d).epsilon(0.08));
    CHECK(floor == Approx(-0.16 * d).margin(2.0));
    // Far from the crater, the plain is untouched.
    CHECK(height(dem, 0, 0) == 0);
    CHECK(height(dem, 127, 127) == 0);

    // Along row 64 eastwards: the height at s = r / R, for the pixel nearest to s.
    const auto along = [&](double s) {
        const int col = 64 + static_cast<int>(std::lround(s * 0.5 * d / pixel));
        return std::pair{(col - 64) * pixel / (0.5 * d), height(dem, col, 64)};
    };
    // The ejecta blanket thins outwards, about as (r/R)^-3 (McGetchin et al. 1973).
    const auto [s12, e12] = along(1.2);
    const auto [s15, e15] = along(1.5);
    const double e19 = along(1.9).second;
    CHECK(e12 > e15);
    CHECK(e15 > e19);
    CHECK(e19 > 0);
    CHECK(e15 == Approx(0.04 * d / (s15 * s15 * s15)).margin(0.005 * d));
    CHECK(e12 == Approx(0.04 * d / (s12 * s12 * s12)).margin(0.005 * d));
    CHECK(height(dem, 127, 64) < 2.0);  // 2.9 R: the blanket has ended

    // The bowl is a paraboloid: the floor rises as (r/R)^2.
    const auto [s05, h05] = along(0.5);
    CHECK(h05 - floor == Approx(0.2 * d * s05 * s05).epsilon(0.1));
}

TEST_CASE("degraded craters are shallower with lower rims", "[synth]") {
    const double d = 3000.0;
    const auto fresh = generate_vesta_tile(single_crater(d, 0.0));
    const auto old = generate_vesta_tile(single_crater(d, 0.6));
    const double fresh_depth = max_height(fresh) - height(fresh, 64, 64);
    const double old_depth = max_height(old) - height(old, 64, 64);
    CHECK(old_depth == Approx(0.4 * fresh_depth).epsilon(0.1));
    CHECK(max_height(old) < 0.5 * max_height(fresh));
    CHECK(max_height(old) > 0);
}

TEST_CASE("a young crater cuts into an old one", "[synth]") {
    auto o = single_crater(6000.0, 0.3);
    o.craters.push_back(Crater{64.5, 64.5, 1000.0, 0.0, 0});
    const auto both = generate_vesta_tile(o);
    const auto old = generate_vesta_tile(single_crater(6000.0, 0.3));
    // The young crater's floor lies about 0.16 D below the old floor it formed on.
    const double drop = height(old, 64, 64) - height(both, 64, 64);
    CHECK(drop > 0.12 * 1000.0);
    CHECK(drop < 0.2 * 1000.0);
    // Outside the young crater's ejecta the old crater is unchanged.
    CHECK(height(both, 64, 110) == height(old, 64, 110));
}

TEST_CASE("the crater population follows the power law, oldest first", "[synth]") {
    const VestaTileOptions o;  // 512x512 with its margin: thousands of craters
    const auto craters = terrain::synth::vesta_crater_population(o);
    REQUIRE(craters.size() > 1000);
    std::size_t over_2dmin = 0, over_4dmin = 0;
    for (std::size_t i = 0; i < craters.size(); ++i) {
        const auto& c = craters[i];
        REQUIRE(c.diameter >= o.min_diameter);
        REQUIRE(c.diameter <= o.max_diameter);
        REQUIRE(c.degradation >= 0);
        REQUIRE(c.degradation < 1);
        if (i > 0) REQUIRE(c.age <= craters[i - 1].age);
        over_2dmin += c.diameter >= 2 * o.min_diameter;
        over_4dmin += c.diameter >= 4 * o.min_diameter;
    }
    // Cumulative N(>=D) ~ D^-2: doubling D quarters the count (binomial sd about 0.01).
    const double n = static_cast<double>(craters.size());
    CHECK(over_2dmin / n == Approx(0.25).margin(0.04));
    CHECK(over_4dmin / n == Approx(0.0625).margin(0.02));

    // Craters inside the tile match the density: N(>=300 m) = 0.05 * 0.3^-2 per km^2.
    std::size_t inside = 0;
    for (const auto& c : craters)
        inside += c.col >= 0 && c.col < o.width && c.row >= 0 && c.row < o.height;
    const double side_km = o.width * 255.0 * std::numbers::pi / 180.0 / 64.0;
    const double expected = o.crater_density * std::pow(0.3, -2.0) * side_km * side_km;
    CHECK(inside == Approx(expected).epsilon(0.15));

    // Old craters are more degraded than young ones of the same size.
    const auto young = std::find_if(craters.rbegin(), craters.rend(),
                                    [](const Crater& c) { return c.diameter < 500; });
    const auto oldest = std::find_if(craters.begin(), craters.end(),
                                     [](const Crater& c) { return c.diameter < 500; });
    REQUIRE(young != craters.rend());
    REQUIRE(oldest != craters.end());
    CHECK(oldest->degradation > young->degradation);
}

TEST_CASE("invalid tile options are refused with terrain::Error", "[synth]") {
    auto o = small_tile();
    o.width = 1;
    CHECK_THROWS_AS(generate_vesta_tile(o), terrain::Error);
    o = small_tile();
    o.center_lat = 89;
    CHECK_THROWS_AS(generate_vesta_tile(o), terrain::Error);
    o = small_tile();
    o.min_diameter = 20000;
    CHECK_THROWS_AS(generate_vesta_tile(o), terrain::Error);
    o = small_tile();
    o.craters.push_back(Crater{10, 10, -5, 0, 0});
    CHECK_THROWS_AS(generate_vesta_tile(o), terrain::Error);
    o = small_tile();
    o.crater_density = std::nan("");
    CHECK_THROWS_WITH(generate_vesta_tile(o), Catch::Contains("crater_density"));
}

TEST_CASE("progress reaches 1 and cancelling stops the generation", "[synth]") {
    double last = -1;
    bool increasing = true;
    generate_vesta_tile(small_tile(), [&](double f, std::string_view) {
        increasing = increasing && f >= last;
        last = f;
        return true;
    });
    CHECK(increasing);
    CHECK(last == 1.0);
    CHECK_THROWS_AS(
        generate_vesta_tile(small_tile(), [](double, std::string_view) { return false; }),
        terrain::Error);
}

TEST_CASE("terrain synth writes the tile as a PDS3 DEM", "[synth]") {
    const auto dir = terrain::test::scratch_dir("synth_cli");
    const std::string label = (dir / "tile.lbl").string();
    const auto r = terrain::test::run_cli(
        {"synth", "-o", label, "--width", "64", "--height", "48", "--seed", "7", "-q"});
    CHECK(r.status == 0);
    CHECK(r.err.empty());
    CHECK_THAT(r.out, Catch::Contains(label) && Catch::Contains("tile.img"));
    const auto dem = terrain::io::read_dem(label);
    CHECK(dem.width == 64);
    CHECK(dem.height == 48);
    CHECK(dem.body.name == "Vesta");
    CHECK(dem.elevation == terrain::ElevationKind::radius);
    auto o = small_tile(64);
    o.height = 48;
    o.seed = 7;
    CHECK(dem.values == generate_vesta_tile(o).values);

    // Existing files are kept unless --overwrite.
    const auto again = terrain::test::run_cli({"synth", "-o", label, "-q"});
    CHECK(again.status == 1);
    CHECK_THAT(again.err, Catch::Contains("already exists") && Catch::Contains("--overwrite"));
    CHECK(terrain::io::read_dem(label).width == 64);
    const auto replaced =
        terrain::test::run_cli({"synth", "-o", label, "--width", "32", "--overwrite", "-q"});
    CHECK(replaced.status == 0);
    CHECK(terrain::io::read_dem(label).width == 32);

    const auto bad = terrain::test::run_cli({"synth", "-q"});
    CHECK(bad.status == 2);
}

TEST_CASE("the Vesta sample is the default synth tile", "[synth]") {
    const std::string path = terrain::test::sample("vesta_hamo_tile.lbl");
    REQUIRE(std::filesystem::exists(path));
    const auto sample = terrain::io::read_dem(path);
    const auto generated = generate_vesta_tile();
    CHECK(sample.body.name == "Vesta");
    CHECK(sample.elevation == terrain::ElevationKind::radius);
    REQUIRE(sample.values.size() == generated.values.size());
    CHECK(sample.values == generated.values);
    for (int i = 0; i < 6; ++i)
        CHECK(sample.transform[i] == Approx(generated.transform[i]).epsilon(1e-9).margin(1e-9));
}
