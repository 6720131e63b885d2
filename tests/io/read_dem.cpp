#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <limits>

#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/read_dem.hpp"

using namespace terrain;
using terrain::test::RasterSpec;

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();

RasterSpec utm_ramp(int w, int h) {
    RasterSpec s;
    s.width = w;
    s.height = h;
    s.crs = "EPSG:32611";
    s.geotransform = {500000, 30, 0, 3800000, 0, -30};
    for (int i = 0; i < w * h; ++i) s.values.push_back(100 + i);
    return s;
}
}  // namespace

TEST_CASE("read_dem reads values, geotransform and CRS of a GeoTIFF", "[read_dem]") {
    const auto dir = test::scratch_dir("read_dem_basic");
    const auto path = test::write_raster(dir / "ramp.tif", utm_ramp(5, 4));
    const Dem dem = io::read_dem(path);
    CHECK(dem.width == 5);
    CHECK(dem.height == 4);
    CHECK(dem.has_transform);
    CHECK(dem.transform[1] == 30);
    CHECK(dem.body.name == "Earth");
    CHECK(dem.elevation == ElevationKind::height);
    CHECK(dem.at(0, 0) == 100);
    CHECK(dem.at(4, 3) == 119);
}

TEST_CASE("read_dem applies scale and offset and turns NoData into holes", "[read_dem]") {
    const auto dir = test::scratch_dir("read_dem_scale");
    RasterSpec s;
    s.type = "Int16";
    s.crs = "+proj=eqc +R=1737400 +no_defs";
    s.geotransform = {0, 100, 0, 0, 0, -100};
    s.values = {0, 10, -32768, 4, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    s.nodata = -32768;
    s.scale = 0.5;
    s.offset = 1737400;
    const Dem dem = io::read_dem(test::write_raster(dir / "moon.tif", s));
    CHECK(dem.at(0, 0) == 1737400);
    CHECK(dem.at(1, 0) == 1737405);
    CHECK_FALSE(dem.valid(2, 0));
    CHECK(dem.body.name == "Moon");
    CHECK(dem.elevation == ElevationKind::radius);
    CHECK(dem.elevation_detected);
    CHECK(dem.height_at(1, 0) == Approx(5));
}

TEST_CASE("read_dem on the real LOLA PDS3 product", "[read_dem][real_data]") {
    const auto path = test::real_data("moon_lola_ldem4/LDEM_4.LBL");
    REQUIRE(path.has_value());  // tests/data is in the repository
    const Dem dem = io::read_dem(*path);
    CHECK(dem.width == 1440);
    CHECK(dem.height == 720);
    CHECK(dem.body.name == "Moon");
    CHECK(dem.body.semi_major_axis == 1737400);
    CHECK(dem.elevation == ElevationKind::radius);
    // The label gives MINIMUM = -17758 and MAXIMUM = 21008 DN.
    double lo = 1e300, hi = -1e300;
    for (double v : dem.values) lo = std::min(lo, v), hi = std::max(hi, v);
    CHECK(lo == Approx(1737400 + 0.5 * -17758).margin(1));  // the label rounds MINIMUM
    CHECK(hi == 1737400 + 0.5 * 21008);
}

TEST_CASE("read_dem on the bundled samples", "[read_dem]") {
    const Dem moon = io::read_dem(test::sample("moon_ldem4_copernicus.tif"));
    CHECK(moon.body.name == "Moon");
    CHECK(moon.elevation == ElevationKind::radius);

    const Dem mars = io::read_dem(test::sample("mars_hirise_crop.tif"));
    CHECK(mars.body.is_local_grid());
    CHECK(mars.elevation == ElevationKind::height);
    CHECK(mars.width == 70);
    CHECK(mars.height == 120);

    const Dem vesta = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    CHECK(vesta.body.name == "Vesta");
    CHECK(vesta.body.semi_major_axis == 255000);
    CHECK(vesta.elevation == ElevationKind::radius);
}

TEST_CASE("read_dem: forced elevation kind and pixel size", "[read_dem]") {
    const auto dir = test::scratch_dir("read_dem_forced");
    RasterSpec s;
    s.values.assign(16, 5.0);
    const auto path = test::write_raster(dir / "plain.tif", s);
    io::ReadDemOptions options;
    options.pixel_size = 2.5;
    options.elevation = ElevationKind::height;
    const Dem dem = io::read_dem(path, options);
    CHECK(dem.transform[1] == 2.5);
    CHECK(dem.transform[5] == -2.5);
    CHECK_FALSE(dem.elevation_detected);
    options.elevation = ElevationKind::radius;  // no CRS: no body to have a radius
    CHECK_THROWS_AS(io::read_dem(path, options), Error);
}

TEST_CASE("read_dem rejects bad input with one clear message", "[read_dem][bad_input]") {
    const auto dir = test::scratch_dir("read_dem_bad");
    auto message_of = [](const std::string& path, io::ReadDemOptions options = {}) {
        try {
            io::read_dem(path, options);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    using Catch::Matchers::Contains;

    CHECK_THAT(message_of((dir / "missing.tif").string()), Contains("does not exist"));

    std::ofstream(dir / "text.tif") << "this is not a raster\n";
    CHECK_THAT(message_of((dir / "text.tif").string()), Contains("not a raster"));

    RasterSpec ok = utm_ramp(4, 4);
    const auto good = test::write_raster(dir / "good.tif", ok);
    io::ReadDemOptions band2;
    band2.band = 2;
    CHECK_THAT(message_of(good, band2), Contains("band 2 does not exist"));

    RasterSpec all_nodata = utm_ramp(4, 4);
    all_nodata.nodata = -9999;
    all_nodata.values.assign(16, -9999);
    CHECK_THAT(message_of(test::write_raster(dir / "nodata.tif", all_nodata)),
               Contains("no valid pixel"));

    RasterSpec one = utm_ramp(1, 1);
    CHECK_THAT(message_of(test::write_raster(dir / "one.tif", one)), Contains("1x1"));

    RasterSpec nan = utm_ramp(4, 4);
    nan.values[5] = kNaN;
    const auto nan_path = test::write_raster(dir / "nan.tif", nan);
    CHECK_THAT(message_of(nan_path), Contains("NaN") && Contains("col 1, row 1"));
    io::ReadDemOptions as_holes;
    as_holes.nan_as_nodata = true;
    const Dem holes = io::read_dem(nan_path, as_holes);
    CHECK_FALSE(holes.valid(1, 1));
    CHECK(holes.valid(0, 0));

    // NaN declared as NoData is an ordinary hole.
    nan.nodata = kNaN;
    CHECK_FALSE(io::read_dem(test::write_raster(dir / "nan_nodata.tif", nan)).valid(1, 1));
}

TEST_CASE("detect_elevation_kind: radius only near the body's radius", "[read_dem]") {
    Body vesta{"Vesta", 255000, 0, true};
    CHECK(io::detect_elevation_kind(vesta, 230000, 280000) == ElevationKind::radius);
    CHECK(io::detect_elevation_kind(vesta, -22000, 19000) == ElevationKind::height);
    Body earth{"Earth", 6378137, 1 / 298.257223563, true};
    CHECK(io::detect_elevation_kind(earth, -400, 8848) == ElevationKind::height);
    CHECK(io::detect_elevation_kind(Body{}, 3e6, 3.1e6) == ElevationKind::height);
}
