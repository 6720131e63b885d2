#pragma once
// Progress reporting, after GDAL's GDALProgressFunc: the library calls the callback with
// the completed fraction in [0,1]; the callback returns false to cancel. The library never
// prints. ScaledProgress maps a sub-task's [0,1] onto a slice of the parent's range.

#include <functional>
#include <string_view>

namespace terrain {

using ProgressFn = std::function<bool(double fraction, std::string_view message)>;

// Calls `fn` if set; throws terrain::Error("cancelled") when the callback asks to stop.
void report_progress(const ProgressFn& fn, double fraction, std::string_view message = {});

// A callback for the [begin,end] slice of `parent`.
ProgressFn scaled_progress(const ProgressFn& parent, double begin, double end);

}  // namespace terrain
