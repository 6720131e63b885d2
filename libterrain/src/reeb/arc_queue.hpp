#pragma once
// Private: the queue of candidate arcs for the simplification (simplify.cpp), by key:
// persistence first, then arc id (ties by id).

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "terrain/internal/core/indices.hpp"
#include "terrain/internal/core/release.hpp"

namespace terrain::reeb::internal {

using detail::i32;

// Queued arcs by key (persistence bits, then the arc id in the low half), in two parts: the
// first candidates, sorted once and read in order (most of them are cancelled with the key
// they started with), and a 4-ary min-heap for the keys set later, each arc at most once there
// (re-keying moves its entry). An arc re-keyed or dropped leaves its sorted entry behind: the
// caller skips such entries (a sorted entry stands while its arc is queued and not in the
// heap: every key set after the first goes to the heap).
class ArcQueue {
  public:
    static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // above any key
    // The key of arc a: the persistence's order-preserving bits (a persistence is never
    // negative), then the arc id (ties by id).
    static std::uint64_t key_of(float persistence, i32 a) {
        return (std::uint64_t{std::bit_cast<std::uint32_t>(persistence)} << 32) |
               static_cast<std::uint32_t>(a);
    }
    static i32 arc_of(std::uint64_t key) { return static_cast<i32>(key & 0xffffffffu); }

    // Room for every arc's first key is reserved, not touched: the pages of the keys seeded
    // become resident as they are written, and no growth copies them (a copy was half as
    // many keys again, at the peak of the simplification's memory).
    // The heap's room too (each arc is in it at most once), untouched until used: it never
    // grows by a copy of itself, which at its peak was its size again. The heap's slots are
    // made once the first keys are sorted and cut to their arc ids (seal()): the sort is the
    // peak of the cancellations' memory. So the heap (set, erase, pop, in_heap) is used only
    // after seal(), with no first keys if there are none.
    void init(std::size_t arcs) {
        arcs_ = arcs;
        sorted_.reserve(arcs);
        heap_.reserve(arcs);
    }
    std::size_t bytes() const {
        return heap_.size() * sizeof(std::uint64_t) + slot_.capacity() * sizeof(i32) +
               (sealed_ ? count_ * sizeof(std::uint32_t) : sorted_.size() * sizeof(std::uint64_t));
    }
    void release() {
        detail::release(slot_);
        detail::release(heap_);
        detail::release(sorted_);
        count_ = next_ = 0;
    }
    // The first candidates, in increasing arc order, then sorted by seal().
    void seed(std::uint64_t key) { sorted_.push_back(key); }
    void seal() {
        // The keys are unique (the arc id is their low half), so sorting them whole is the
        // stable sort of their high halves in the order seeded. In place: at the peak of the
        // simplification's memory a second buffer is 8 bytes a candidate (about one a pixel
        // on a noisy grid). One pass of American flag sort on the top 11 bits puts each key
        // in its bucket by swaps, then each bucket is sorted.
        constexpr int kShift = 53;
        constexpr std::size_t kBuckets = std::size_t{1} << (64 - kShift);
        std::vector<std::size_t> begin(kBuckets + 1, 0);
        for (const std::uint64_t k : sorted_) ++begin[(k >> kShift) + 1];
        for (std::size_t b = 0; b < kBuckets; ++b) begin[b + 1] += begin[b];
        std::vector<std::size_t> next(begin.begin(), begin.end() - 1);
        for (std::size_t b = 0; b < kBuckets; ++b)
            while (next[b] < begin[b + 1]) {
                const std::size_t home = sorted_[next[b]] >> kShift;
                if (home == b)
                    ++next[b];
                else
                    std::swap(sorted_[next[b]], sorted_[next[home]++]);
            }
        // (The buckets on every thread: the keys are unique, so each bucket's order is the same.)
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, kBuckets, 1),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t b = r.begin(); b < r.end(); ++b)
                                  std::sort(
                                      sorted_.begin() + static_cast<std::ptrdiff_t>(begin[b]),
                                      sorted_.begin() + static_cast<std::ptrdiff_t>(begin[b + 1]));
                          });
        // Sorted, each entry keeps only its arc id (4 bytes), written over the front half of
        // the keys in order (entry k's id lands on bytes a key before it or k itself held,
        // already read); the back half's pages go back to the system. The caller knows each
        // arc's key: an entry's is its arc's while the arc is queued outside the heap.
        count_ = sorted_.size();
        unsigned char* const bytes = reinterpret_cast<unsigned char*>(sorted_.data());
        for (std::size_t k = 0; k < count_; ++k) {
            const auto id = static_cast<std::uint32_t>(sorted_[k]);
            std::memcpy(bytes + k * sizeof(id), &id, sizeof(id));
        }
        detail::PagesBehind(bytes + count_ * sizeof(std::uint32_t))
            .before(bytes + count_ * sizeof(std::uint64_t));
        sealed_ = true;
        next_ = 0;
        behind_ = detail::PagesBehind(bytes);
        slot_.assign(arcs_, detail::kNone);
    }
    // The arc of the next sorted entry (kNone after the last), and of the one `ahead` places
    // further.
    i32 sorted_front() const { return sorted_ahead(0); }
    i32 sorted_ahead(std::size_t ahead) const {
        if (next_ + ahead >= count_) return detail::kNone;
        std::uint32_t id;
        std::memcpy(
            &id,
            reinterpret_cast<const unsigned char*>(sorted_.data()) + (next_ + ahead) * sizeof(id),
            sizeof(id));
        return static_cast<i32>(id);
    }
    // (The entries passed are read no more: their pages go back to the system as the
    // cancellations go, 4 bytes a first candidate.)
    void skip_sorted() {
        if ((++next_ & 0xffff) == 0)
            behind_.before(reinterpret_cast<const unsigned char*>(sorted_.data()) +
                           next_ * sizeof(std::uint32_t));
    }
    // Whether arc a has an entry in the heap (its sorted entry, if any, is then stale).
    bool in_heap(i32 a) const { return slot_[detail::idx(a)] != detail::kNone; }
    void prefetch_slot(i32 a) const { __builtin_prefetch(&slot_[detail::idx(a)]); }
    // Entries still queued (sorted ones to come and the heap's), stale ones included.
    std::size_t pending() const { return count_ - next_ + heap_.size(); }
    std::uint64_t top() const { return heap_.empty() ? kEmpty : heap_.front(); }
    // Queues arc `key & 0xffffffff` with this key, or moves it there.
    void set(std::uint64_t key) {
        const std::size_t a = arc(key);
        if (slot_[a] == detail::kNone) {
            heap_.push_back(key);
            up(heap_.size() - 1, key);
        } else if (key < heap_[detail::idx(slot_[a])]) {
            up(detail::idx(slot_[a]), key);
        } else {
            down(detail::idx(slot_[a]), key);
        }
    }
    void erase(i32 a) {
        const i32 i = slot_[detail::idx(a)];
        if (i == detail::kNone) return;
        slot_[detail::idx(a)] = detail::kNone;
        const std::uint64_t last = heap_.back();
        heap_.pop_back();
        if (detail::idx(i) == heap_.size()) return;
        if (last < heap_[detail::idx(i)])
            up(detail::idx(i), last);
        else
            down(detail::idx(i), last);
    }
    // The root's hole goes down to a leaf along the smaller children, and the last entry
    // comes up from there (it mostly belongs near the leaves).
    std::uint64_t pop() {
        const std::uint64_t key = heap_.front(), last = heap_.back();
        slot_[arc(key)] = detail::kNone;
        heap_.pop_back();
        const std::size_t n = heap_.size();
        if (n == 0) return key;
        std::size_t i = 0;
        for (std::size_t m; (m = smallest_child(i)) != 0; i = m) place(i, heap_[m]);
        up(i, last);
        return key;
    }

  private:
    static std::size_t arc(std::uint64_t key) { return static_cast<std::uint32_t>(key); }
    void place(std::size_t i, std::uint64_t key) {
        heap_[i] = key;
        slot_[arc(key)] = static_cast<i32>(i);
    }
    // Puts `key` at slot i or above (below) it, moving the entries in its way.
    void up(std::size_t i, std::uint64_t key) {
        while (i > 0) {
            const std::size_t parent = (i - 1) / 4;
            if (heap_[parent] <= key) break;
            place(i, heap_[parent]);
            i = parent;
        }
        place(i, key);
    }
    void down(std::size_t i, std::uint64_t key) {
        for (std::size_t m; (m = smallest_child(i)) != 0 && heap_[m] < key; i = m)
            place(i, heap_[m]);
        place(i, key);
    }
    // The slot of i's smallest child, 0 when it has none.
    std::size_t smallest_child(std::size_t i) const {
        const std::size_t c = 4 * i + 1, n = heap_.size();
        if (c >= n) return 0;
        std::size_t m = c;
        for (std::size_t j = c + 1; j < std::min(c + 4, n); ++j)
            if (heap_[j] < heap_[m]) m = j;
        return m;
    }

    std::vector<std::uint64_t> heap_;
    std::vector<i32> slot_;              // each arc's slot in heap_, kNone when not there
    std::vector<std::uint64_t> sorted_;  // the first keys; once sealed, count_ arc ids
    std::size_t arcs_ = 0, count_ = 0;
    bool sealed_ = false;
    std::size_t next_ = 0;  // entries next_.. are still to come
    detail::PagesBehind behind_;
};

}  // namespace terrain::reeb::internal
