#include <catch2/catch.hpp>

#include <cpl_conv.h>
#include <ogr_spatialref.h>

#include <string>

#include "terrain/geo/body.hpp"
#include "terrain/synth/crater_field.hpp"
#include "terrain/synth/vesta_crs.hpp"

namespace {

// The same CRS built with OGR, as GDAL's PDS driver builds it for a Vesta label.
std::string ogr_wkt(double center_lon, double standard_parallel) {
    OGRSpatialReference srs;
    srs.SetEquirectangular2(0.0, center_lon, standard_parallel, 0.0, 0.0);
    srs.SetProjCS("EQUIRECTANGULAR VESTA");
    srs.SetGeogCS("GCS_VESTA", "D_VESTA", "VESTA_localRadius", terrain::synth::kVestaRadius, 0.0,
                  "Reference_Meridian", 0.0);
    char* wkt = nullptr;
    const char* options[] = {"FORMAT=WKT2_2019", nullptr};
    REQUIRE(srs.exportToWkt(&wkt, options) == OGRERR_NONE);
    std::string text = wkt;
    CPLFree(wkt);
    return text;
}

}  // namespace

TEST_CASE("The Vesta tile's CRS is the text OGR exports for it", "[synth]") {
    for (const auto& [lon, lat] :
         {std::pair{150.0, -30.0}, std::pair{0.0, 0.0}, std::pair{359.999, 12.345678901234567},
          std::pair{20.5, -79.99999999}, std::pair{1.0 / 3.0, 2.0 / 3.0}}) {
        CAPTURE(lon, lat);
        CHECK(terrain::synth::vesta_equirectangular_wkt(lon, lat) == ogr_wkt(lon, lat));
    }
    const auto body =
        terrain::geo::body_from_crs(terrain::synth::vesta_equirectangular_wkt(150, -30));
    CHECK(body.name == "Vesta");
    CHECK(body.semi_major_axis == terrain::synth::kVestaRadius);
}
