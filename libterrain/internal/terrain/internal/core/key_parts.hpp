#pragma once
// Private: a serial scatter made parallel without atomics: `body(i, key)` for every item i in
// order whose key (the place it writes) is not negative, the keys cut into consecutive parts,
// each part on one thread. Every part reads every item's key (a pass in memory order) and
// takes the items whose key falls in it, so that each place is written by one thread only and
// in the items' order: the result is the serial pass's, whatever the threads.
//
// For passes over a whole grid's nodes that write to random places (a counting sort, a
// histogram, a CSR fill): on one thread the writes wait on memory one after the other; here
// the threads share them without the locked instructions of atomic increments, which stall
// on every cache miss (docs/performance.md, "Scatters by parts of the keys").

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

#include "terrain/internal/core/pass_progress.hpp"

namespace terrain::detail {

// `key(i)`: item i's place in [0, keys), or negative to skip it. The items go a chunk at a
// time (each chunk's parts in parallel), `pass` reporting before each chunk.
template <class Key, class Body>
void scatter_by_key_parts(std::size_t items, std::size_t keys, const PassProgress& pass,
                          const Key& key, const Body& body) {
    // Small passes, or one thread: the serial pass. Else twice the threads (parts of
    // different speed even out), at most 16: each part reads every key.
    constexpr std::size_t kSmall = std::size_t{1} << 16, kChunk = std::size_t{1} << 22;
    const auto threads = static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
    const std::size_t parts =
        items < kSmall || threads < 2 ? 1 : std::min<std::size_t>(16, 2 * threads);
    for (std::size_t first = 0; first < items; first += kChunk) {
        pass.at(first, items);
        const std::size_t last = std::min(items, first + kChunk);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, parts, 1),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t p = r.begin(); p < r.end(); ++p) {
                                  const auto lo = static_cast<std::int64_t>(keys * p / parts),
                                             hi = static_cast<std::int64_t>(keys * (p + 1) / parts);
                                  for (std::size_t i = first; i < last; ++i) {
                                      const std::int64_t k = key(i);
                                      if (k >= lo && k < hi) body(i, static_cast<std::size_t>(k));
                                  }
                              }
                          });
    }
}

// A counting sort by parts of the keys, in two steps (the caller sizes its output between):
// count_by_key_parts turns `offsets` (keys + 1 zeros) into each key's first slot;
// place_by_key_parts then calls `place(i, slot)` for every item i with a key, its slot among
// its key's in item order (the serial sort's).
template <class Key>
void count_by_key_parts(std::size_t items, std::vector<std::int32_t>& offsets,
                        const PassProgress& pass, const Key& key) {
    scatter_by_key_parts(items, offsets.size() - 1, pass, key,
                         [&](std::size_t, std::size_t k) { ++offsets[k + 1]; });
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
}
template <class Key, class Place>
void place_by_key_parts(std::size_t items, const std::vector<std::int32_t>& offsets,
                        const PassProgress& pass, const Key& key, const Place& place) {
    std::vector<std::int32_t> fill(offsets.begin(), offsets.end() - 1);
    scatter_by_key_parts(items, fill.size(), pass, key, [&](std::size_t i, std::size_t k) {
        place(i, static_cast<std::size_t>(fill[k]++));
    });
}

}  // namespace terrain::detail
