#pragma once
// Private: give memory back. `v = {}` on a std::vector picks the initializer-list assignment,
// which empties it but keeps its capacity. Not installed.

#include <sys/mman.h>

#include <cstdint>

namespace terrain::detail {

template <class Container>
void release(Container& c) {
    Container().swap(c);
}

// The pages of an array that a pass reads in order, given back behind it: before(p) says that
// the elements before p are read for the last time, and the whole pieces of 2 MiB (aligned,
// a transparent huge page: none is split) before p not given back yet go to the system (their
// memory reads as zeros after; the array stays allocated and is freed as usual). An array
// read once, front to back, then leaves the resident set as the pass goes instead of at its
// end.
class PagesBehind {
  public:
    static constexpr std::uintptr_t kPiece = std::uintptr_t{2} << 20;

    PagesBehind() = default;
    explicit PagesBehind(const void* begin) : done_(up(address(begin))) {}

    void before(const void* p) {
        if (done_ == 0) return;
        const std::uintptr_t to = address(p) & ~(kPiece - 1);
        if (to <= done_) return;
        ::madvise(reinterpret_cast<void*>(done_), to - done_, MADV_DONTNEED);
        done_ = to;
    }

  private:
    static std::uintptr_t address(const void* p) { return reinterpret_cast<std::uintptr_t>(p); }
    static std::uintptr_t up(std::uintptr_t a) {
        return a == 0 ? 0 : (a + kPiece - 1) & ~(kPiece - 1);
    }
    std::uintptr_t done_ = 0;  // given back up to here (0: nothing to give back)
};

}  // namespace terrain::detail
