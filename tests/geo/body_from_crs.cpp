#include <catch2/catch.hpp>

#include "terrain/core/error.hpp"
#include "terrain/geo/body.hpp"

using terrain::geo::body_from_crs;

TEST_CASE("Earth from EPSG codes, with the WGS84 ellipsoid", "[body]") {
    for (const char* code : {"EPSG:4326", "EPSG:32611", "EPSG:3857"}) {
        const auto body = body_from_crs(code);
        CHECK(body.name == "Earth");
        CHECK(body.semi_major_axis == Approx(6378137.0));
        CHECK(body.flattening == Approx(1 / 298.257223563));
        CHECK(body.has_crs);
    }
    // An Earth ellipsoid with no Earth-like name is still Earth by its size.
    CHECK(body_from_crs("+proj=longlat +ellps=bessel +no_defs").name == "Earth");
}

TEST_CASE("planetary CRSs from IAU_2015 and ESRI codes", "[body]") {
    const auto moon = body_from_crs("IAU_2015:30100");
    CHECK(moon.name == "Moon");
    CHECK(moon.semi_major_axis == Approx(1737400));
    CHECK(moon.flattening == 0);

    const auto mars_sphere = body_from_crs("IAU_2015:49900");
    CHECK(mars_sphere.name == "Mars");
    CHECK(mars_sphere.flattening == 0);
    const auto mars = body_from_crs("IAU_2015:49901");  // the ellipsoid
    CHECK(mars.name == "Mars");
    CHECK(mars.semi_major_axis == Approx(3396190));
    CHECK(mars.flattening == Approx((3396190.0 - 3376200.0) / 3396190.0));

    const auto vesta = body_from_crs("IAU_2015:200000400");
    CHECK(vesta.name == "Vesta");
    CHECK(vesta.semi_major_axis == 255000);

    const auto mars_esri = body_from_crs("ESRI:104905");
    CHECK(mars_esri.name == "Mars");
    const auto moon_esri = body_from_crs("ESRI:104903");
    CHECK(moon_esri.name == "Moon");
    CHECK(moon_esri.semi_major_axis == Approx(1737400));
}

TEST_CASE("a PROJ string with only a radius is named by that radius", "[body]") {
    CHECK(body_from_crs("+proj=eqc +R=255000 +no_defs").name == "Vesta");
    CHECK(body_from_crs("+proj=eqc +R=1737400 +no_defs").name == "Moon");
    CHECK(body_from_crs("+proj=eqc +R=123456 +no_defs").name == "unknown");
}

TEST_CASE("no CRS is a local metric grid, garbage is an error", "[body]") {
    const auto local = body_from_crs("");
    CHECK(local.is_local_grid());
    CHECK(local.semi_major_axis == 0);
    CHECK_THROWS_AS(body_from_crs("not a crs at all"), terrain::Error);
}

TEST_CASE("names win over radii, and Earth keywords come last", "[body]") {
    CHECK(terrain::geo::identify_body_name("GCS_MOON D_MOON MOON", 1737400) == "Moon");
    CHECK(terrain::geo::identify_body_name("MEAN EARTH/POLAR AXIS Moon", 1737400) == "Moon");
    CHECK(terrain::geo::identify_body_name("GCS_VESTA", 289000) == "Vesta");
    CHECK(terrain::geo::identify_body_name("Krassowsky 1940", 6378245) == "Earth");
}
