// The memory check (terrain/core/memory_budget.hpp): what the process holds already counts
// as available to the work it is part of.
#include <catch2/catch.hpp>

#include "terrain/core/error.hpp"
#include "terrain/core/memory_budget.hpp"

using namespace terrain;

TEST_CASE("check_memory counts what the process holds already as available", "[memory]") {
    const auto available = available_memory();
    REQUIRE(available);  // (/proc/meminfo: Linux)
    const double free_bytes = double(*available);
    // 1 GB over what is available: refused, unless 2 GB of it are held already (a DEM read
    // before its valid pixels are counted); 1 GB of slack either way for the system's churn.
    const double over = free_bytes + 1e9;
    CHECK_THROWS_AS(check_memory("a test", over), Error);
    CHECK_NOTHROW(check_memory("a test", over, 0, 2e9));
    // The caller's limit is on the whole, held or not.
    CHECK_THROWS_AS(check_memory("a test", 3e9, std::uint64_t(2e9), 2e9), Error);
}

namespace {
int releases = 0;
}

TEST_CASE("release_free_memory calls the release a program registered", "[memory]") {
    releases = 0;
    release_free_memory();  // none registered in the tests: glibc's trim alone
    CHECK(releases == 0);
    set_free_memory_release([] { ++releases; });
    release_free_memory();
    release_free_memory();
    CHECK(releases == 2);
    set_free_memory_release(nullptr);
    release_free_memory();
    CHECK(releases == 2);
}
