#include "terrain/core/progress.hpp"

#include <algorithm>

#include "terrain/core/error.hpp"

namespace terrain {

void report_progress(const ProgressFn& fn, double fraction, std::string_view message) {
    if (fn && !fn(std::clamp(fraction, 0.0, 1.0), message))
        throw Error("progress", "cancelled by the caller");
}

ProgressFn scaled_progress(const ProgressFn& parent, double begin, double end) {
    if (!parent) return {};
    return [parent, begin, end](double fraction, std::string_view message) {
        return parent(begin + (end - begin) * std::clamp(fraction, 0.0, 1.0), message);
    };
}

}  // namespace terrain
