#include "terrain/core/dem.hpp"

namespace terrain {

const char* to_string(ElevationKind kind) {
    return kind == ElevationKind::radius ? "radius" : "height";
}

}  // namespace terrain
