#include "terrain/synth/vesta_crs.hpp"

#include <cstdio>

#include "terrain/synth/crater_field.hpp"

namespace terrain::synth {
namespace {

// A number as OGR writes it in WKT: 15 significant digits, no trailing zeros.
std::string wkt_number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.15g", v);
    return text;
}

}  // namespace

std::string vesta_equirectangular_wkt(double center_lon, double standard_parallel) {
    const std::string degree = R"(ANGLEUNIT["degree",0.0174532925199433])";
    const std::string metre = R"(LENGTHUNIT["metre",1])";
    const std::string metre_id = R"(LENGTHUNIT["metre",1,ID["EPSG",9001]])";
    return R"(PROJCRS["EQUIRECTANGULAR VESTA",BASEGEOGCRS["GCS_VESTA",DATUM["D_VESTA",)"
           R"(ELLIPSOID["VESTA_localRadius",)" +
           wkt_number(kVestaRadius) + ",0," + metre_id +
           R"(]],PRIMEM["Reference_Meridian",0,ANGLEUNIT["degree",0.0174532925199433,)"
           R"(ID["EPSG",9122]]]],CONVERSION["Equidistant Cylindrical",)"
           R"(METHOD["Equidistant Cylindrical",ID["EPSG",1028]],)"
           R"(PARAMETER["Latitude of 1st standard parallel",)" +
           wkt_number(standard_parallel) + "," + degree + R"(,ID["EPSG",8823]],)" +
           R"(PARAMETER["Longitude of natural origin",)" + wkt_number(center_lon) + "," + degree +
           R"(,ID["EPSG",8802]],PARAMETER["False easting",0,)" + metre +
           R"(,ID["EPSG",8806]],PARAMETER["False northing",0,)" + metre +
           R"w(,ID["EPSG",8807]]],CS[Cartesian,2],AXIS["(E)",east,ORDER[1],)w" + metre_id +
           R"w(],AXIS["(N)",north,ORDER[2],)w" + metre_id + "]]";
}

}  // namespace terrain::synth
