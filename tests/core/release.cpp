// Pieces of memory given back behind a pass (core/release.hpp), and ranked bits
// (core/ranked_bits.hpp).

#include <catch2/catch.hpp>
#include <cstdint>
#include <random>
#include <vector>

#include "support/test_support.hpp"
#include "terrain/internal/core/ranked_bits.hpp"
#include "terrain/internal/core/release.hpp"

using terrain::detail::PagesBehind;

TEST_CASE("PagesBehind gives back the whole 2 MiB pieces before the pass, nothing at or after it",
          "[core]") {
    // 32 MiB of ints, every one touched (a mapping of its own: what is given back reads zero).
    std::vector<int> v(std::size_t{8} << 20, 7);
    const auto at = [&](std::size_t i) { return reinterpret_cast<std::uintptr_t>(v.data() + i); };
    const std::size_t per_piece = PagesBehind::kPiece / sizeof(int);
    // The first element on a piece's edge.
    std::size_t first = 0;
    while (at(first) % PagesBehind::kPiece != 0) ++first;
    PagesBehind behind(v.data());
    // Inside the first whole piece: nothing yet.
    behind.before(v.data() + first + per_piece - 1);
    CHECK(v[first] == 7);
    // Half way, not on a piece's edge.
    const std::size_t half = v.size() / 2 + 17;
    behind.before(v.data() + half);
    std::size_t edge = half;  // the first element of the piece the pass is in
    while (at(edge) % PagesBehind::kPiece != 0) --edge;
    REQUIRE(edge > first);
    // Before the first whole piece (partly before the array's start): kept. The whole pieces
    // before the pass: given back (zeros, not resident). The piece the pass is in and all after
    // it: kept, every value.
    std::size_t kept_before = 0, given = 0, kept_after = 0;
    for (std::size_t i = 0; i < first; ++i) kept_before += v[i] == 7;
    for (std::size_t i = first; i < edge; i += 1024) {
        CHECK(terrain::test::resident_bytes(v.data() + i, 1) == 0);  // (before it is read: a read
                                                                     // maps a page of zeros)
        given += v[i] == 0;
    }
    for (std::size_t i = edge; i < v.size(); ++i) kept_after += v[i] == 7;
    CHECK(kept_before == first);
    CHECK(given == (edge - first + 1023) / 1024);
    CHECK(kept_after == v.size() - edge);
    // Going back does nothing; an empty array gives nothing back.
    behind.before(v.data() + 10);
    CHECK(v[edge] == 7);
    PagesBehind none(nullptr);
    none.before(v.data() + v.size());
    CHECK(v[v.size() - 1] == 7);
}

TEST_CASE("Ranked bits: a member's rank is the count of members below it", "[core]") {
    std::mt19937 rng(5);
    // Sizes around the 64-bit words' edges, and members at both ends of words.
    for (const std::size_t n : {std::size_t{1}, std::size_t{63}, std::size_t{64}, std::size_t{65},
                                std::size_t{1000}, std::size_t{4097}}) {
        terrain::detail::RankedBits bits(n);
        std::vector<bool> model(n, false);
        std::bernoulli_distribution member(0.3);
        for (std::size_t i = 0; i < n; ++i)
            if (i == 0 || i == n - 1 || i % 64 == 63 || member(rng)) {
                bits.set(i);
                model[i] = true;
            }
        bits.count();
        std::size_t below = 0;
        for (std::size_t i = 0; i < n; ++i) {
            REQUIRE(bits.test(i) == model[i]);
            REQUIRE(bits.rank(i) == below);
            below += model[i];
        }
        CHECK(bits.members() == below);
    }
}
