#include "terrain/core/dem.hpp"

namespace terrain {

const char* to_string(ElevationKind kind) {
    return name_of(kElevationNames, kind);
}

const char* to_string(CrsKind kind) {
    switch (kind) {
        case CrsKind::geographic:
            return "geographic";
        case CrsKind::projected:
            return "projected";
        case CrsKind::other:
            return "other";
        default:
            return "none";
    }
}

bool Dem::georef_current() const {
    if (crs_wkt.empty()) return georef.crs_wkt.empty();  // nothing depends on the grid then
    return georef.crs_wkt == crs_wkt && georef.transform == transform && georef.width == width &&
           georef.height == height;
}

}  // namespace terrain
