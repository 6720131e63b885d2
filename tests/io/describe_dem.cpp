#include <catch2/catch.hpp>

#include "support/test_support.hpp"
#include "terrain/io/describe_dem.hpp"
#include "terrain/io/read_dem.hpp"

using namespace terrain;

TEST_CASE("describe_dem on LDEM_4: the Moon, radii, 7581 m pixels, global",
          "[describe_dem][real_data]") {
    const auto path = test::real_data("moon_lola_ldem4/LDEM_4.LBL");
    REQUIRE(path.has_value());  // tests/data is in the repository
    const auto d = io::describe_dem(io::read_dem(*path));
    CHECK(d.body.name == "Moon");
    CHECK(d.body.semi_major_axis == 1737400);
    CHECK(d.elevation == ElevationKind::radius);
    CHECK(d.pixel_width_m == Approx(7581).margin(1));
    CHECK(d.global_longitude);
    CHECK(d.lon_max - d.lon_min == Approx(360));
    CHECK(d.lat_max == Approx(90).margin(0.01));
    CHECK(d.lat_min == Approx(-90).margin(0.01));
    CHECK(d.nodata_fraction == 0);
}

TEST_CASE("describe_dem on the bundled global Moon and a crop", "[describe_dem]") {
    const auto global = io::describe_dem(io::read_dem(test::sample("moon_ldem1_global.tif")));
    CHECK(global.global_longitude);
    CHECK(global.pixel_width_m == Approx(4 * 7580.84));

    const auto crop = io::describe_dem(io::read_dem(test::sample("moon_ldem4_copernicus.tif")));
    CHECK_FALSE(crop.global_longitude);
    CHECK(crop.lon_span == Approx(128 * 0.25).epsilon(1e-4));
    // Copernicus crater, 9.6 N 20.1 W, lies inside the crop.
    CHECK(crop.lat_min < 9.6);
    CHECK(crop.lat_max > 9.6);
    const double lon = -20.1;
    CHECK(((crop.lon_min < lon && crop.lon_max > lon) ||
           (crop.lon_min < lon + 360 && crop.lon_max > lon + 360)));
}

TEST_CASE("describe_dem on the SRTM tile: Earth, 30 m, heights", "[describe_dem][real_data]") {
    const auto path = test::real_data("earth/bigtujunga_srtm30m_utm11.tif");
    REQUIRE(path.has_value());  // tests/data is in the repository
    const auto d = io::describe_dem(io::read_dem(*path));
    CHECK(d.body.name == "Earth");
    CHECK(d.elevation == ElevationKind::height);
    CHECK(d.pixel_width_m == Approx(30).epsilon(0.01));
    CHECK(d.min_value == 315);
    CHECK(d.max_value == 2295);
    CHECK_FALSE(d.global_longitude);
    CHECK(d.lat_min > 34);
    CHECK(d.lat_max < 34.5);
}

TEST_CASE("describe_dem: a geographic grid gets metres at its centre latitude", "[describe_dem]") {
    const auto dir = test::scratch_dir("describe_geographic");
    test::RasterSpec s;
    s.crs = "EPSG:4326";
    s.geotransform = {10, 0.001, 0, 60.002, 0, -0.001};  // centre at 60 N
    s.values.assign(16, 100);
    const auto d = io::describe_dem(io::read_dem(test::write_raster(dir / "ll.tif", s)));
    // One thousandth of a degree: 111.4 m north-south, about half of 111.4 m east-west at 60 N.
    CHECK(d.pixel_height_m == Approx(111.4).epsilon(0.005));
    CHECK(d.pixel_width_m == Approx(55.8).epsilon(0.005));
    CHECK(d.lon_min == Approx(10));
}

TEST_CASE("describe_dem: a local grid has no body and no extent", "[describe_dem]") {
    const auto d = io::describe_dem(io::read_dem(test::sample("mars_hirise_crop.tif")));
    CHECK(d.body.is_local_grid());
    CHECK_FALSE(d.has_geographic_extent);
    CHECK(d.pixel_width_m == Approx(1.01));
    CHECK(d.min_value > 750);
    CHECK(d.max_value < 795);
}
