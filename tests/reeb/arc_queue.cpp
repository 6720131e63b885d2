#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "../../libterrain/src/reeb/arc_queue.hpp"

using terrain::reeb::internal::ArcQueue;

TEST_CASE("The candidates' queue: first keys sorted once, persistence then arc id", "[simplify]") {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> persistence(0.f, 1000.f);
    // (A million keys fill 8 MiB: the ids written over them and the pages given back behind
    // and after them span many 2 MiB pieces.)
    const int n = GENERATE(5000, 1 << 20);
    ArcQueue q;
    q.init(n);
    std::vector<std::uint64_t> keys;
    for (int a = 0; a < n; ++a) {
        // Many ties in persistence: the arc id decides.
        const float p = a % 3 == 0 ? 7.5f : persistence(rng);
        keys.push_back(ArcQueue::key_of(p, a));
        q.seed(keys.back());
    }
    CHECK(q.bytes() == n * sizeof(std::uint64_t));
    q.seal();
    // Sealed, the entries are the arcs in key order, 4 bytes each, and the heap's slots.
    CHECK(q.bytes() == n * (sizeof(std::uint32_t) + sizeof(std::int32_t)));
    CHECK(q.pending() == static_cast<std::size_t>(n));
    std::sort(keys.begin(), keys.end());
    CHECK(q.sorted_ahead(3) == ArcQueue::arc_of(keys[3]));
    for (const std::uint64_t k : keys) {
        REQUIRE(q.sorted_front() == ArcQueue::arc_of(k));
        REQUIRE_FALSE(q.in_heap(ArcQueue::arc_of(k)));
        q.skip_sorted();
    }
    CHECK(q.sorted_front() == terrain::detail::kNone);
    CHECK(q.sorted_ahead(0) == terrain::detail::kNone);
    CHECK(q.pending() == 0);
    // An arc set later is in the heap.
    q.set(ArcQueue::key_of(3.f, 17));
    CHECK(q.in_heap(17));
    CHECK_FALSE(q.in_heap(18));
    CHECK(q.pop() == ArcQueue::key_of(3.f, 17));
    CHECK_FALSE(q.in_heap(17));
    CHECK(ArcQueue::arc_of(ArcQueue::key_of(2.5f, 1234)) == 1234);
    CHECK(ArcQueue::key_of(1.f, 9) < ArcQueue::key_of(2.f, 0));
    CHECK(ArcQueue::key_of(1.f, 0) < ArcQueue::key_of(1.f, 9));
}

TEST_CASE("The candidates' heap: set, re-key, erase and pop agree with a sorted model",
          "[simplify]") {
    std::mt19937 rng(11);
    constexpr int n = 300;
    std::uniform_int_distribution<int> arc(0, n - 1), op(0, 9);
    std::uniform_real_distribution<float> persistence(0.f, 50.f);
    ArcQueue q;
    q.init(n);
    q.seal();                            // no first keys: the heap alone
    std::map<int, std::uint64_t> model;  // arc -> its key while queued
    const auto smallest = [&] {
        std::uint64_t m = ArcQueue::kEmpty;
        for (const auto& [a, k] : model) m = std::min(m, k);
        return m;
    };
    for (int step = 0; step < 20000; ++step) {
        const int o = op(rng);
        if (o < 6) {  // queue or re-key (up or down)
            const int a = arc(rng);
            const std::uint64_t k = ArcQueue::key_of(persistence(rng), a);
            q.set(k);
            model[a] = k;
        } else if (o < 8) {
            const int a = arc(rng);
            q.erase(a);  // queued or not
            model.erase(a);
        } else if (!model.empty()) {
            const std::uint64_t k = q.pop();
            REQUIRE(k == smallest());
            model.erase(ArcQueue::arc_of(k));
        }
        REQUIRE(q.top() == smallest());
    }
}
