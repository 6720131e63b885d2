#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "../../libterrain/src/core/disjoint_sets.hpp"

using terrain::detail::DisjointSets;
using terrain::detail::find_root;
using terrain::detail::i32;
using terrain::detail::kNone;

TEST_CASE("Disjoint sets keep the root each caller asks for", "[core]") {
    DisjointSets<i32> sets(6);
    CHECK(sets.size() == 6);
    // unite(keep, other): keep's root stays the root, whichever set is larger.
    CHECK(sets.unite(4, 1) == 4);
    CHECK(sets.unite(4, 2) == 4);
    CHECK(sets.unite(5, 4) == 5);
    for (const i32 x : {1, 2, 4, 5}) CHECK(sets.find(x) == 5);
    CHECK(sets.is_root(5));
    CHECK_FALSE(sets.is_root(4));
    CHECK(sets.find(0) == 0);
    CHECK(sets.find(3) == 3);
    // unite_to_smaller: the smaller of the two roots wins, in either argument order.
    CHECK(sets.unite_to_smaller(2, 3) == 3);
    CHECK(sets.find(5) == 3);
    CHECK(sets.unite_to_smaller(0, 1) == 0);
    for (i32 x = 0; x < 6; ++x) CHECK(sets.find(x) == 0);
    CHECK(sets.unite(3, 0) == 0);  // already one set: nothing changes
    sets.flatten();
    for (i32 x = 0; x < 6; ++x) CHECK(sets.parent(x) == 0);
    CHECK(sets.add() == 6);
    CHECK(sets.find(6) == 6);
}

TEST_CASE("Disjoint sets with members added one by one", "[core]") {
    DisjointSets<std::uint32_t> unsigned_sets(3);
    unsigned_sets.unite(2u, 0u);
    CHECK(unsigned_sets.find(0u) == 2u);
    DisjointSets<i32> sets;
    CHECK(sets.empty());
    sets.reset_empty(4);
    CHECK_FALSE(sets.contains(1));
    sets.make_set(1);
    sets.make_set(3);
    CHECK(sets.contains(1));
    CHECK_FALSE(sets.contains(2));
    CHECK(sets.unite_to_smaller(3, 1) == 1);
    CHECK(sets.find(3) == 1);
}

TEST_CASE("Disjoint sets agree with a plain labelling under random unions", "[core]") {
    constexpr i32 n = 200;
    std::mt19937 rng(7);
    std::uniform_int_distribution<i32> pick(0, n - 1);
    DisjointSets<i32> sets(n);
    std::vector<i32> label(n);  // each element's set, relabelled eagerly: the keep's root wins
    for (i32 x = 0; x < n; ++x) label[static_cast<std::size_t>(x)] = x;
    for (int k = 0; k < 150; ++k) {
        const i32 a = pick(rng), b = pick(rng);
        const i32 la = label[static_cast<std::size_t>(a)], lb = label[static_cast<std::size_t>(b)];
        const i32 root = k % 2 ? sets.unite(a, b) : sets.unite_to_smaller(a, b);
        const i32 expect = k % 2 ? la : std::min(la, lb);
        CHECK(root == expect);
        for (auto& l : label)
            if (l == la || l == lb) l = expect;
    }
    for (i32 x = 0; x < n; ++x) CHECK(sets.find(x) == label[static_cast<std::size_t>(x)]);
}

TEST_CASE("find_root follows kNone-rooted parent links and compresses them", "[core]") {
    // 0 <- 1 <- 2 <- 3, and 4 alone.
    std::vector<i32> parent{kNone, 0, 1, 2, kNone};
    CHECK(find_root(parent, 3) == 0);
    CHECK(parent == std::vector<i32>{kNone, 0, 0, 0, kNone});
    CHECK(find_root(parent, 4) == 4);
    CHECK(find_root(parent, 0) == 0);
}
