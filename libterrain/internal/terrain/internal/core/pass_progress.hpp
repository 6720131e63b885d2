#pragma once
// Private: progress through long passes, so that a run on a whole global grid reports every
// second or so in every stage (docs/performance.md, "Progress on long runs").
//   - PassProgress: a serial pass over n items, reported as a slice [begin, end] of a
//     callback every 2^18 items (a few milliseconds of a pass: the call costs nothing), or
//     every 2^shift items (rows of a grid: 2^5).
//   - assign_in_slices, copy_in_slices: a large vector filled 2^18 elements at a time,
//     reported after each: the first touch of a large block's pages is a silence of its own
//     (the kernel zeroes each fresh page; a virtual machine also backs it then).
//     Its pages are touched first on every thread (touch_pages): a fresh page costs the same
//     on each, so two threads take it in half the time.
//   - parallel_slices: a parallel pass over n items cut into at most 64 consecutive slices,
//     each run by tbb::parallel_for, reported after each. The body sees the same items as
//     one parallel_for over the whole range, so the results do not change.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <string_view>
#include <vector>

#include "terrain/core/progress.hpp"

namespace terrain::detail {

class PassProgress {
  public:
    PassProgress(const ProgressFn& fn, double begin, double end, std::string_view message,
                 int shift = 18)
        : fn_(fn),
          mask_((std::size_t{1} << shift) - 1),
          begin_(begin),
          end_(end),
          message_(message) {}
    // Item i of n is next.
    void at(std::size_t i, std::size_t n) const {
        if (fn_ && (i & mask_) == 0)
            report_progress(fn_, begin_ + (end_ - begin_) * double(i) / double(n), message_);
    }

  private:
    const ProgressFn& fn_;
    std::size_t mask_;
    double begin_, end_;
    std::string_view message_;
};

// The pages of [first, first + bytes) touched (a zero byte written in each), on every thread,
// before a serial pass writes them all: the first touch of fresh memory is slow, and two
// threads share it (docs/performance.md, "Large blocks are made a slice at a time"). The
// storage is raw (reserved, its elements not made yet) or about to be overwritten.
inline void touch_pages(void* first, std::size_t bytes) {
    constexpr std::size_t kPage = 4096, kChunk = std::size_t{2} << 20, kWorth = kChunk * 4;
    if (bytes < kWorth) return;
    auto* base = static_cast<unsigned char*>(first);
    const std::size_t chunks = (bytes + kChunk - 1) / kChunk;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t c = r.begin(); c < r.end(); ++c) {
                              const std::size_t end = std::min(bytes, (c + 1) * kChunk);
                              for (std::size_t at = c * kChunk; at < end; at += kPage)
                                  *static_cast<volatile unsigned char*>(base + at) = 0;
                          }
                      });
}

// v becomes n copies of value, with the capacity n (as std::vector<T>(n, value)), or `room`
// when larger (reserved, not touched: no page of it resident until used).
template <class T>
void assign_in_slices(std::vector<T>& v, std::size_t n, const T& value, const PassProgress& pass,
                      std::size_t room = 0) {
    std::vector<T>().swap(v);
    v.reserve(std::max(n, room));
    touch_pages(v.data(), n * sizeof(T));
    constexpr std::size_t kSlice = std::size_t{1} << 18;
    for (std::size_t at = 0; at < n;) {
        pass.at(at, n);
        at = std::min(n, at + kSlice);
        v.resize(at, value);
    }
}

// v becomes a copy of [first, first + n), with the capacity n.
template <class T>
void copy_in_slices(std::vector<T>& v, const T* first, std::size_t n, const PassProgress& pass) {
    std::vector<T>().swap(v);
    v.reserve(n);
    touch_pages(v.data(), n * sizeof(T));
    constexpr std::size_t kSlice = std::size_t{1} << 18;
    for (std::size_t at = 0; at < n;) {
        pass.at(at, n);
        const std::size_t next = std::min(n, at + kSlice);
        v.insert(v.end(), first + at, first + next);
        at = next;
    }
}

// body(tbb::blocked_range<Index>) over [0, n) with `grain`, in slices; the slice [begin, end]
// of `fn` reported after each slice (none when fn is empty: one parallel_for).
template <class Index, class Body>
void parallel_slices(Index n, Index grain, const ProgressFn& fn, double begin, double end,
                     std::string_view message, const Body& body) {
    if (!fn) {
        tbb::parallel_for(tbb::blocked_range<Index>(0, n, grain), body);
        return;
    }
    constexpr Index kSlices = 64;
    const Index step = std::max<Index>(grain, (n + kSlices - 1) / kSlices);
    for (Index first = 0; first < n; first += step) {
        const Index last = std::min<Index>(n, first + step);
        tbb::parallel_for(tbb::blocked_range<Index>(first, last, grain), body);
        report_progress(fn, begin + (end - begin) * double(last) / double(n), message);
    }
}

}  // namespace terrain::detail
