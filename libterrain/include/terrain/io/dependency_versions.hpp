#pragma once
// Versions of the libraries terrain was built with (the io layer, which links them).

#include <string>
#include <utility>
#include <vector>

namespace terrain {

// (library, version) pairs: GDAL, PROJ, CGAL, GeographicLib, FreeType, Boost, Eigen, TBB.
std::vector<std::pair<std::string, std::string>> dependency_versions();

}  // namespace terrain
