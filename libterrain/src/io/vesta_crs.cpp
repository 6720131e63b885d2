#include "terrain/io/vesta_crs.hpp"

#include <cpl_conv.h>
#include <ogr_spatialref.h>

#include "terrain/core/error.hpp"
#include "terrain/synth/crater_field.hpp"

namespace terrain::io {

std::string vesta_equirectangular_wkt(double center_lon, double standard_parallel) {
    OGRSpatialReference srs;
    srs.SetEquirectangular2(0.0, center_lon, standard_parallel, 0.0, 0.0);
    srs.SetProjCS("EQUIRECTANGULAR VESTA");
    srs.SetGeogCS("GCS_VESTA", "D_VESTA", "VESTA_localRadius", synth::kVestaRadius, 0.0,
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

}  // namespace terrain::io
