#include "terrain/synth/vesta_crs.hpp"
#include "terrain/internal/core/significant.hpp"

#include "terrain/synth/crater_field.hpp"

namespace terrain::synth {
namespace {

// A number as OGR writes it in WKT: 15 significant digits, no trailing zeros.
std::string wkt_number(double v) {
    return terrain::detail::significant(v, 15);
}

}  // namespace

std::string vesta_equirectangular_wkt(double center_lon, double standard_parallel) {
    const std::string degree = R"w(ANGLEUNIT["degree",0.0174532925199433])w";
    const std::string metre = R"w(LENGTHUNIT["metre",1])w";
    const std::string metre_id = R"w(LENGTHUNIT["metre",1,ID["EPSG",9001]])w";
    return R"w(PROJCRS["EQUIRECTANGULAR VESTA",BASEGEOGCRS["GCS_VESTA",DATUM["D_VESTA",)w"
           R"w(ELLIPSOID["VESTA_localRadius",)w" +
           wkt_number(kVestaRadius) + ",0," + metre_id +
           R"w(]],PRIMEM["Reference_Meridian",0,ANGLEUNIT["degree",0.0174532925199433,)w"
           R"w(ID["EPSG",9122]]]],CONVERSION["Equidistant Cylindrical",)w"
           R"w(METHOD["Equidistant Cylindrical",ID["EPSG",1028]],)w"
           R"w(PARAMETER["Latitude of 1st standard parallel",)w" +
           wkt_number(standard_parallel) + "," + degree + R"w(,ID["EPSG",8823]],)w" +
           R"w(PARAMETER["Longitude of natural origin",)w" + wkt_number(center_lon) + "," + degree +
           R"w(,ID["EPSG",8802]],PARAMETER["False easting",0,)w" + metre +
           R"w(,ID["EPSG",8806]],PARAMETER["False northing",0,)w" + metre +
           R"w(,ID["EPSG",8807]]],CS[Cartesian,2],AXIS["(E)",east,ORDER[1],)w" + metre_id +
           R"w(],AXIS["(N)",north,ORDER[2],)w" + metre_id + "]]";
}

}  // namespace terrain::synth
