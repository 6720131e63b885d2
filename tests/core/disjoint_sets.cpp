#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "terrain/internal/core/disjoint_sets.hpp"

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

TEST_CASE("find_root_shared finds every node's root from many threads at once", "[core]") {
    // A forest of long chains (each node links to an earlier node of its tree, or is a root),
    // searched from every node at once on several threads: the roots a serial walk finds,
    // and afterwards every link still names a node of its own tree.
    std::mt19937 random(7);
    const std::size_t n = std::size_t{1} << 20;
    std::vector<i32> parent(n, kNone), tree(n);
    for (std::size_t x = 0; x < n; ++x) {
        if (x % 1000 == 0) {  // a root
            tree[x] = static_cast<i32>(x);
            continue;
        }
        // mostly the node just before (long paths), sometimes any earlier node of the tree
        const std::size_t up = random() % 4 == 0 ? x - 1 - random() % (x % 1000) : x - 1;
        parent[x] = static_cast<i32>(up);
        tree[x] = tree[up];
    }
    std::vector<i32> found(n, kNone);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, 256), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i < r.end(); ++i) {
                const std::size_t x = (i * 7919) % n;  // out of order
                found[x] = terrain::detail::find_root_shared(parent, static_cast<i32>(x));
            }
        });
    CHECK(found == tree);
    std::size_t outside = 0;
    for (std::size_t x = 0; x < n; ++x)
        outside += parent[x] != kNone && tree[static_cast<std::size_t>(parent[x])] != tree[x];
    CHECK(outside == 0);
}
