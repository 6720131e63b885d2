#include <GeographicLib/UTMUPS.hpp>
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <thread>
#include <vector>

#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/geo/body.hpp"
#include "terrain/geo/georeference.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;

namespace {

// A flat w x h grid in `crs` with geotransform `t`.
Dem flat_grid(const std::string& crs, const GeoTransform& t, int w, int h) {
    Dem dem;
    dem.width = w;
    dem.height = h;
    dem.crs_wkt = crs;
    dem.transform = t;
    dem.has_transform = true;
    dem.values.assign(std::size_t(w) * h, 100.0);
    return dem;
}

}  // namespace

TEST_CASE("georeference: CRS kind and linear unit", "[georef]") {
    const GeoTransform t{0, 1, 0, 0, 0, -1};
    const auto none = geo::georeference("", t, 4, 4, geo::body_from_crs(""));
    CHECK(none.kind == CrsKind::none);
    CHECK(none.linear_unit_m == 1);
    CHECK_FALSE(none.lonlat);
    CHECK_FALSE(none.output_lonlat);
    CHECK_FALSE(none.has_geographic_extent);

    const auto ll = geo::georeference("EPSG:4326", {7, 0.01, 0, 46, 0, -0.01}, 10, 10,
                                      geo::body_from_crs("EPSG:4326"));
    CHECK(ll.kind == CrsKind::geographic);
    CHECK(ll.linear_unit_m == 1);
    CHECK(ll.has_geographic_extent);
    CHECK(ll.lon_min == Approx(7));
    CHECK(ll.lat_max == Approx(46));

    const auto utm = geo::georeference("EPSG:32632", {500000, 30, 0, 5000000, 0, -30}, 10, 10,
                                       geo::body_from_crs("EPSG:32632"));
    CHECK(utm.kind == CrsKind::projected);
    CHECK(utm.linear_unit_m == 1);
    CHECK(utm.pixel_width_m == Approx(30));

    // NAD83 / New York Long Island in US survey feet.
    const auto feet = geo::georeference("EPSG:2263", {1000000, 10, 0, 200000, 0, -10}, 10, 10,
                                        geo::body_from_crs("EPSG:2263"));
    CHECK(feet.kind == CrsKind::projected);
    CHECK(feet.linear_unit_m == Approx(1200.0 / 3937.0));
    CHECK(feet.pixel_width_m == Approx(10 * 1200.0 / 3937.0));
}

TEST_CASE("georeference: the lon/lat mapping agrees with GeographicLib's UTM", "[georef]") {
    Dem dem = flat_grid("EPSG:32632", {480000, 100, 0, 5000000, 0, -100}, 20, 20);
    geo::georeference(dem);
    REQUIRE(dem.georef.lonlat);
    std::vector<double> x, y;
    for (int i = 0; i < 20; ++i) {
        const auto p = dem.map_xy(i + 0.5, 19.5 - i);
        x.push_back(p[0]);
        y.push_back(p[1]);
    }
    auto lon = x, lat = y;
    std::vector<std::uint8_t> ok(x.size(), 0);
    CHECK(dem.georef.lonlat->to_lonlat(x.size(), lon.data(), lat.data(), ok.data()));
    for (std::size_t i = 0; i < x.size(); ++i) {
        double expected_lat, expected_lon;
        GeographicLib::UTMUPS::Reverse(32, true, x[i], y[i], expected_lat, expected_lon);
        CHECK(ok[i] == 1);
        CHECK(lon[i] == Approx(expected_lon).margin(1e-9));
        CHECK(lat[i] == Approx(expected_lat).margin(1e-9));
    }
    // A point with no longitude/latitude is flagged and the call says so.
    double bad_x[2] = {500000, std::numeric_limits<double>::infinity()};
    double bad_y[2] = {5000000, 0};
    std::uint8_t bad_ok[2] = {0, 1};
    CHECK_FALSE(dem.georef.lonlat->to_lonlat(2, bad_x, bad_y, bad_ok));
    CHECK(bad_ok[1] == 0);
}

TEST_CASE("georeference: one mapping gives the same doubles on every thread", "[georef]") {
    Dem dem = flat_grid("EPSG:32611", {400000, 30, 0, 3800000, 0, -30}, 500, 64);
    geo::georeference(dem);
    const LonLatMapping& mapping = *dem.georef.lonlat;
    auto row = [&](int r, std::vector<double>& x, std::vector<double>& y) {
        x.resize(500);
        y.resize(500);
        for (int c = 0; c < 500; ++c) {
            const auto p = dem.map_xy(c + 0.5, r + 0.5);
            x[std::size_t(c)] = p[0];
            y[std::size_t(c)] = p[1];
        }
        return mapping.to_lonlat(x.size(), x.data(), y.data());
    };
    std::vector<std::vector<double>> serial_x(64), serial_y(64);
    for (int r = 0; r < 64; ++r) REQUIRE(row(r, serial_x[r], serial_y[r]));
    std::vector<std::vector<double>> par_x(64), par_y(64);
    std::vector<int> good(4, 1);
    std::vector<std::thread> threads;
    for (int k = 0; k < 4; ++k)
        threads.emplace_back([&, k] {
            for (int r = k; r < 64; r += 4) good[k] = good[k] && row(r, par_x[r], par_y[r]);
        });
    for (auto& t : threads) t.join();
    CHECK(good == std::vector<int>(4, 1));
    CHECK(par_x == serial_x);
    CHECK(par_y == serial_y);
}

TEST_CASE("georeference: global grids close and touch the poles", "[georef]") {
    const Dem global = io::read_dem(test::sample("moon_ldem1_global.tif"));
    CHECK(global.georef_current());
    CHECK(global.georef.global_longitude);
    CHECK(global.georef.pole_row[0]);
    CHECK(global.georef.pole_row[1]);
    const Dem crop = io::read_dem(test::sample("moon_ldem4_copernicus.tif"));
    CHECK_FALSE(crop.georef.global_longitude);
    CHECK_FALSE(crop.georef.pole_row[0]);
    CHECK_FALSE(crop.georef.pole_row[1]);
}

TEST_CASE("georeference: outputs' lon/lat, EPSG:4326 on Earth, unwrapped around the centre",
          "[georef]") {
    Dem utm = flat_grid("EPSG:32632", {480000, 100, 0, 5000000, 0, -100}, 20, 20);
    geo::georeference(utm);
    REQUIRE(utm.georef.output_lonlat);
    CHECK(utm.georef.output_lonlat->lonlat_crs_wkt().find("WGS 84") != std::string::npos);
    CHECK(utm.georef.output_lonlat->lonlat_crs_wkt().find("\n") == std::string::npos);

    // A global 0..360 grid keeps 0..360 (its centre is at 180 E).
    const Dem moon = io::read_dem(test::sample("moon_ldem1_global.tif"));
    REQUIRE(moon.georef.output_lonlat);
    std::vector<double> x, y;
    for (int c = 0; c < moon.width; c += 7) {
        const auto p = moon.map_xy(c + 0.5, moon.height / 2.0);
        x.push_back(p[0]);
        y.push_back(p[1]);
    }
    REQUIRE(moon.georef.output_lonlat->to_lonlat(x.size(), x.data(), y.data()));
    const double centre = moon.georef.lon_min + 180;
    for (double lon : x) CHECK(std::abs(lon - centre) <= 180);
}

TEST_CASE("georeference: a grid changed after reading needs a new one", "[georef]") {
    Dem dem = io::read_dem(test::sample("moon_ldem4_copernicus.tif"));
    REQUIRE(dem.georef_current());
    Dem moved = dem;
    moved.transform[0] += moved.transform[1];
    CHECK_FALSE(moved.georef_current());
    CHECK_THROWS_AS(mesh::dem_to_mesh(moved), Error);
    geo::georeference(moved);
    CHECK(moved.georef_current());
    CHECK(mesh::dem_to_mesh(moved).vertex_count() == mesh::dem_to_mesh(dem).vertex_count());
    // A grid made in memory without CRS needs none.
    Dem local = flat_grid("", {0, 1, 0, 0, 0, -1}, 4, 4);
    CHECK(local.georef_current());
    CHECK(mesh::dem_to_mesh(local).vertex_count() == 16);
    // One with a CRS does.
    Dem planetary = flat_grid("IAU_2015:30100", {0, 1, 0, 10, 0, -1}, 4, 4);
    CHECK_FALSE(planetary.georef_current());
    CHECK_THROWS_AS(mesh::dem_to_mesh(planetary), Error);
}
