#include "terrain/io/dependency_versions.hpp"

#include <CGAL/version.h>
#include <ft2build.h>
#include FT_FREETYPE_H
#include <GeographicLib/Config.h>
#include <gdal.h>
#include <oneapi/tbb/version.h>
#include <proj.h>
#include <Eigen/Core>
#include <boost/version.hpp>

namespace terrain {

std::vector<std::pair<std::string, std::string>> dependency_versions() {
    const auto dotted = [](int a, int b, int c) {
        return std::to_string(a) + "." + std::to_string(b) + "." + std::to_string(c);
    };
    return {
        {"GDAL", GDALVersionInfo("RELEASE_NAME")},
        {"PROJ", dotted(PROJ_VERSION_MAJOR, PROJ_VERSION_MINOR, PROJ_VERSION_PATCH)},
        {"CGAL", CGAL_VERSION_STR},
        {"GeographicLib", GEOGRAPHICLIB_VERSION_STRING},
        {"FreeType", dotted(FREETYPE_MAJOR, FREETYPE_MINOR, FREETYPE_PATCH)},
        {"Boost", dotted(BOOST_VERSION / 100000, BOOST_VERSION / 100 % 1000, BOOST_VERSION % 100)},
        {"Eigen", dotted(EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION)},
        {"TBB", dotted(TBB_VERSION_MAJOR, TBB_VERSION_MINOR, 0)},
    };
}

}  // namespace terrain
