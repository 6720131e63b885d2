#pragma once
// Version of terrain (the libraries it was built with: terrain/io/dependency_versions.hpp).

#include <string>

namespace terrain {

// "0.1.0"
std::string version();

}  // namespace terrain
