#pragma once
// Private: a monotone priority queue over 64-bit keys (a radix heap), for floodings whose
// costs never fall below the last one taken (shortest paths with non-negative steps).
//
// Items wait in 65 buckets by the highest bit in which their key differs from the last key
// popped (`last_`): bucket 0 holds keys equal to it, bucket b keys that first differ from it
// in bit b - 1. A pop takes bucket 0; when it is empty, the lowest non-empty bucket's least key
// becomes `last_` and the bucket's items move to lower buckets, each at most 64 times in its
// life. Pushes append to a vector; pops scan vectors in memory order: unlike a binary heap
// over millions of items, no walk down a tree of cache misses.
//
// A key below `last_` (a flooding whose costs tie, ordered further by vertex: a step of cost
// zero to a lower vertex) waits in a small binary heap that is taken first: it is less than
// every key in the buckets, which are all at least `last_`. Pops thus come in the exact order
// of a binary heap over (key, then any order among equal keys).

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace terrain::detail {

// Item: a struct with `std::uint64_t key() const`.
template <class Item>
class RadixHeap {
  public:
    bool empty() const { return size_ == 0; }
    std::size_t size() const { return size_; }

    void push(const Item& item) {
        const std::uint64_t k = item.key();
        ++size_;
        if (k < last_) {
            below_.push_back(item);
            std::push_heap(below_.begin(), below_.end(), greater);
            return;
        }
        put(bucket_of(k), item);
    }

    // The least item (of the items with the least key, any); the heap must not be empty.
    Item pop() {
        --size_;
        if (!below_.empty()) {
            std::pop_heap(below_.begin(), below_.end(), greater);
            const Item top = below_.back();
            below_.pop_back();
            return top;
        }
        if (buckets_[0].empty()) refill();
        const Item top = buckets_[0].back();
        buckets_[0].pop_back();
        return top;
    }

    // The item pop() would return now (nullptr when empty), without taking it: for fetching
    // its memory early. (May move items between buckets, as pop() would next.)
    const Item* peek() {
        if (size_ == 0) return nullptr;
        if (!below_.empty()) return &below_.front();
        if (buckets_[0].empty()) refill();
        return &buckets_[0].back();
    }

  private:
    static bool greater(const Item& a, const Item& b) { return a.key() > b.key(); }

    std::size_t bucket_of(std::uint64_t k) const {
        return k == last_ ? 0 : 64 - static_cast<std::size_t>(std::countl_zero(k ^ last_));
    }

    void put(std::size_t b, const Item& item) {
        buckets_[b].push_back(item);
        if (b > 0) filled_ |= std::uint64_t{1} << (b - 1);
    }

    // Bucket 0 empty: the lowest non-empty bucket's least key becomes last_, its items move down.
    void refill() {
        const auto b = 1 + static_cast<std::size_t>(std::countr_zero(filled_));
        auto& from = buckets_[b];
        std::uint64_t least = from.front().key();
        for (const Item& item : from) least = std::min(least, item.key());
        last_ = least;
        filled_ &= ~(std::uint64_t{1} << (b - 1));
        for (const Item& item : from) put(bucket_of(item.key()), item);
        from.clear();
    }

    std::uint64_t last_ = 0;
    std::size_t size_ = 0;
    std::uint64_t filled_ = 0;  // bit b - 1: bucket b (1 to 64) holds items
    std::array<std::vector<Item>, 65> buckets_;
    std::vector<Item> below_;  // keys below last_, as a binary heap (least on top)
};

}  // namespace terrain::detail
