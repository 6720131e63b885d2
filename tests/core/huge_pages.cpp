// Huge pages (terrain/core/huge_pages.hpp): the tunable added to what the caller set, never
// over a choice of its own.
#include <catch2/catch.hpp>

#include "terrain/core/huge_pages.hpp"

using terrain::tunables_with_huge_pages;

TEST_CASE("the huge page tunable is added to the caller's tunables, never over them",
          "[huge_pages]") {
    CHECK(tunables_with_huge_pages("") == "glibc.malloc.hugetlb=1");
    CHECK(tunables_with_huge_pages("glibc.malloc.arena_max=2") ==
          "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1");
    // The caller's own setting stands, whatever it is.
    CHECK(tunables_with_huge_pages("glibc.malloc.hugetlb=0").empty());
    CHECK(tunables_with_huge_pages("glibc.malloc.arena_max=2:glibc.malloc.hugetlb=2").empty());
}

TEST_CASE("the kernel's huge page mode is one of its three or unknown", "[huge_pages]") {
    const auto mode = terrain::transparent_huge_page_mode();
    CHECK((mode == "always" || mode == "madvise" || mode == "never" || mode.empty()));
    const auto use = terrain::huge_page_use();
    CHECK((use == "huge" || use == "normal"));
    if (mode == "never" || mode.empty()) CHECK(use == "normal");
}
