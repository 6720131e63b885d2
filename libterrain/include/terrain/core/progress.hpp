#pragma once
// Progress reporting, after GDAL's GDALProgressFunc: the library calls the callback with
// the completed fraction in [0,1]; the callback returns false to cancel. The library never
// prints. scaled_progress maps a sub-task's [0,1] onto a slice of the parent's range.

#include <functional>
#include <string_view>

namespace terrain {

using ProgressFn = std::function<bool(double fraction, std::string_view message)>;

// Calls `fn` if set, with `fraction` clamped to [0,1]; throws terrain::Error (stage
// "progress") when the callback returns false.
void report_progress(const ProgressFn& fn, double fraction, std::string_view message = {});

// A callback for the [begin,end] slice of `parent` (its fraction clamped to [0,1] first);
// empty when `parent` is.
ProgressFn scaled_progress(const ProgressFn& parent, double begin, double end);

}  // namespace terrain
