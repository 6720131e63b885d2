#include "terrain/core/error.hpp"

namespace terrain {

Error::Error(const std::string& stage, const std::string& message)
    : std::runtime_error(stage + ": " + message), stage_(stage) {}

}  // namespace terrain
