// Pages given back behind a pass (core/release.hpp).

#include <sys/mman.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "../../libterrain/src/core/release.hpp"

namespace {

// Whether the page holding p is resident.
bool resident(const void* p) {
    const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
    void* start = reinterpret_cast<void*>(reinterpret_cast<std::uintptr_t>(p) & ~(page - 1));
    unsigned char in = 0;
    REQUIRE(::mincore(start, page, &in) == 0);
    return (in & 1) != 0;
}

}  // namespace

TEST_CASE("PagesBehind gives back the whole pages before the pass and nothing at or after it",
          "[core]") {
    const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE)) / sizeof(int);
    // 4 MiB of ints, every one touched (a mapping of its own: what is given back reads zero).
    std::vector<int> v(std::size_t{1} << 20, 7);
    terrain::detail::PagesBehind behind(v.data());
    // Less than the least given back at once: nothing yet.
    behind.before(v.data() + 3 * page + 5);
    CHECK(v[page + 1] == 7);
    // Half way, not on a page's edge.
    const std::size_t half = v.size() / 2 + 17;
    behind.before(v.data() + half);
    // The first page, partly before the array's start, is kept; the pages wholly before the
    // pass are given back (zeros and no longer resident); the page the pass is in and all after
    // it are kept, every value.
    CHECK(v[0] == 7);
    const std::size_t first_given =
        (page - reinterpret_cast<std::uintptr_t>(v.data()) / sizeof(int) % page) % page;
    const std::size_t last_given = half / page * page;  // (the array starts on a page's edge
                                                        // or not: checked with a page's margin)
    for (std::size_t i = first_given + page; i + 2 * page < last_given; i += page) {
        CHECK(!resident(v.data() + i));
        CHECK(v[i] == 0);
    }
    std::size_t kept = 0;
    for (std::size_t i = half; i < v.size(); ++i) kept += v[i] == 7;
    CHECK(kept == v.size() - half);
    // The part of the pass's page before it too.
    const auto bytes = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
    const auto edge = reinterpret_cast<std::uintptr_t>(v.data() + half) & ~(bytes - 1);
    const std::size_t in_page = half - (edge - reinterpret_cast<std::uintptr_t>(v.data())) /
                                           sizeof(int);  // (elements of that page before it)
    REQUIRE(in_page > 0);
    for (std::size_t i = half - in_page; i < half; ++i) CHECK(v[i] == 7);
    CHECK(v[half - in_page - 1] == 0);  // (the element just before that page is given back)
    // Going back does nothing; an empty array gives nothing back.
    behind.before(v.data() + 10);
    CHECK(v[half - 1] == 7);
    terrain::detail::PagesBehind none(nullptr);
    none.before(v.data() + v.size());
    CHECK(v[v.size() - 1] == 7);
}
