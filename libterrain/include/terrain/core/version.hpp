#pragma once
// Version of terrain and of the libraries it was built with.

#include <string>
#include <utility>
#include <vector>

namespace terrain {

// "0.1.0"
std::string version();

// (library, version) pairs: GDAL, PROJ, CGAL, GeographicLib, OpenImageIO, Boost, Eigen, TBB.
std::vector<std::pair<std::string, std::string>> dependency_versions();

}  // namespace terrain
