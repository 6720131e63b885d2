#include <catch2/catch.hpp>

#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <random>
#include <vector>

#include "terrain/internal/core/radix_heap.hpp"

using terrain::detail::RadixHeap;

namespace {

struct Item {
    std::uint32_t cost;  // small integers: many ties, and steps of cost zero
    std::uint32_t vertex;
    std::uint32_t label;
    std::uint64_t key() const { return std::uint64_t{cost} << 32 | vertex; }
    bool operator>(const Item& o) const {
        return key() != o.key() ? key() > o.key() : label > o.label;
    }
};

// A flooding as segment::divide_absorbed runs it (offers queued only when better, stale ones
// skipped when taken) on a random graph from a few seeds; returns the keys in the order taken
// and each vertex's label.
template <class Queue, class Pop>
std::pair<std::vector<std::uint64_t>, std::vector<std::uint32_t>> flood(
    const std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>>& edges,
    const std::vector<std::uint32_t>& seeds, Queue& queue, Pop pop) {
    const std::size_t n = edges.size();
    constexpr auto kInf = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> cost(n, kInf), label(n, 0);
    std::vector<char> final(n, 0);
    std::vector<std::uint64_t> taken;
    for (std::size_t s = 0; s < seeds.size(); ++s) {
        cost[seeds[s]] = 0;
        label[seeds[s]] = static_cast<std::uint32_t>(s + 1);
        queue.push(Item{0, seeds[s], label[seeds[s]]});
    }
    while (!queue.empty()) {
        const Item it = pop(queue);
        if (final[it.vertex] || it.cost != cost[it.vertex] || it.label != label[it.vertex])
            continue;
        final[it.vertex] = 1;
        taken.push_back(it.key());
        for (const auto& [u, w] : edges[it.vertex]) {
            if (final[u]) continue;
            const std::uint32_t c = it.cost + w;
            if (c > cost[u] || (c == cost[u] && it.label >= label[u])) continue;
            cost[u] = c;
            label[u] = it.label;
            queue.push(Item{c, u, it.label});
        }
    }
    return {taken, label};
}

}  // namespace

TEST_CASE("A radix heap takes a flooding's offers in the order a binary heap does", "[core]") {
    std::mt19937 random(7);
    for (int round = 0; round < 20; ++round) {
        const std::size_t n = 2000;
        // Weights 0..3 (zero steps to lower vertices give keys below the last one taken),
        // and in some rounds large ones, so that keys differ in their high bits.
        const std::uint32_t top = round % 4 == 3 ? 1u << 24 : 3;
        std::uniform_int_distribution<std::uint32_t> vertex(0, n - 1), weight(0, top);
        std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> edges(n);
        for (std::size_t e = 0; e < 4 * n; ++e) {
            const auto a = vertex(random), b = vertex(random), w = weight(random);
            edges[a].push_back({b, w});
            edges[b].push_back({a, w});
        }
        const std::vector<std::uint32_t> seeds = {vertex(random), vertex(random), vertex(random)};
        std::priority_queue<Item, std::vector<Item>, std::greater<Item>> binary;
        const auto expected = flood(edges, seeds, binary, [](auto& q) {
            const Item top_item = q.top();
            q.pop();
            return top_item;
        });
        RadixHeap<Item> radix;
        const auto got = flood(edges, seeds, radix, [](auto& q) { return q.pop(); });
        REQUIRE(got.first.size() > n / 2);
        CHECK(got.first == expected.first);
        CHECK(got.second == expected.second);
        CHECK(radix.empty());
        // A peek after each pop, as divide_absorbed fetches the next vertex's memory: it may
        // move items early (the offers pushed next then wait below the new last key), and
        // the order stays the binary heap's.
        RadixHeap<Item> peeked;
        const auto got_peeking = flood(edges, seeds, peeked, [](auto& q) {
            const Item it = q.pop();
            q.peek();
            return it;
        });
        CHECK(got_peeking.first == expected.first);
        CHECK(got_peeking.second == expected.second);
    }
}

TEST_CASE("A radix heap pops keys in order, those below the last taken first", "[core]") {
    RadixHeap<Item> heap;
    for (const std::uint32_t c : {5u, 9u, 5u, 70000u, 6u}) heap.push(Item{c, c % 7, 0});
    CHECK(heap.size() == 5);
    CHECK(heap.pop().cost == 5);
    // Below the last key taken (cost 5, vertex 5): cost 5 at a lower vertex.
    heap.push(Item{5, 1, 0});
    heap.push(Item{5, 0, 0});
    std::vector<std::uint64_t> keys;
    while (!heap.empty()) keys.push_back(heap.pop().key());
    const std::vector<std::uint64_t> expected = {Item{5, 0, 0}.key(), Item{5, 1, 0}.key(),
                                                 Item{5, 5, 0}.key(), Item{6, 6, 0}.key(),
                                                 Item{9, 2, 0}.key(), Item{70000, 0, 0}.key()};
    CHECK(keys == expected);
}

TEST_CASE("A radix heap's peek shows the item its next pop takes", "[core]") {
    std::mt19937 random(11);
    std::uniform_int_distribution<std::uint32_t> cost(0, 40), vertex(0, 999);
    RadixHeap<Item> heap;
    CHECK(heap.peek() == nullptr);
    std::uint64_t last = 0;
    for (int step = 0; step < 5000; ++step) {
        // Pushes at or above the last key taken, and some below it (a tie at a lower vertex).
        for (int k = static_cast<int>(random() % 3); k > 0; --k) {
            const std::uint32_t c = static_cast<std::uint32_t>(last >> 32) + cost(random) % 3;
            heap.push(Item{c, vertex(random), 0});
        }
        if (heap.empty()) continue;
        const Item* next = heap.peek();
        REQUIRE(next != nullptr);
        const std::uint64_t shown = next->key();
        CHECK(heap.peek()->key() == shown);  // a second look changes nothing
        const Item taken = heap.pop();
        CHECK(taken.key() == shown);
        last = taken.key();
    }
    while (!heap.empty()) {
        const std::uint64_t shown = heap.peek()->key();
        CHECK(heap.pop().key() == shown);
    }
    CHECK(heap.peek() == nullptr);
}
