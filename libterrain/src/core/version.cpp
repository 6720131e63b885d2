#include "terrain/core/version.hpp"

#include "terrain/version.hpp"

namespace terrain {

std::string version() {
    return TERRAIN_VERSION_STRING;
}

}  // namespace terrain
