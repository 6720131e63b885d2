#pragma once
// Private: the progress of one pass over n items, reported as a slice [begin, end] of a
// callback every 2^18 items (a few milliseconds of a pass, so the call costs nothing).

#include <cstddef>
#include <string_view>

#include "terrain/core/progress.hpp"

namespace terrain::detail {

class PassProgress {
  public:
    PassProgress(const ProgressFn& fn, double begin, double end, std::string_view message)
        : fn_(fn), begin_(begin), end_(end), message_(message) {}
    // Item i of n is next.
    void at(std::size_t i, std::size_t n) const {
        if (fn_ && (i & kMask) == 0)
            report_progress(fn_, begin_ + (end_ - begin_) * double(i) / double(n), message_);
    }

  private:
    static constexpr std::size_t kMask = (std::size_t{1} << 18) - 1;
    const ProgressFn& fn_;
    double begin_, end_;
    std::string_view message_;
};

}  // namespace terrain::detail
