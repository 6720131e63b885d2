#pragma once
// Lists made from a mesh's triangles on every thread in the order of one pass, and their
// size checked: the adjacency (mesh_adjacency.cpp) and the pinched vertices
// (vertex_repairs.cpp).

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/error.hpp"

namespace terrain::detail {

// Refuses a mesh whose per-corner lists would pass the 32-bit offsets that index them.
inline void check_adjacency_size(std::uint64_t entries, const char* what) {
    if (entries > std::uint64_t{UINT32_MAX})
        throw Error("mesh", "the mesh has " + std::to_string(entries) + " " + what +
                                ", more than 32-bit offsets can index: too large");
}

// Sorts each of the `count` lists lists[offsets[i] .. offsets[i + 1]) and drops its repeats,
// packing them one after the other from the front of `lists`; packed(i, end) is told where
// list i now ends. Returns the packed length.
template <class Packed>
std::size_t pack_sorted_lists(std::vector<std::int32_t>& lists,
                              const std::vector<std::uint32_t>& offsets, std::size_t count,
                              Packed&& packed) {
    std::size_t write = 0;
    for (std::size_t i = 0; i < count; ++i) {
        auto begin = lists.begin() + offsets[i], end = lists.begin() + offsets[i + 1];
        std::sort(begin, end);
        end = std::unique(begin, end);
        for (auto it = begin; it != end; ++it) lists[write++] = *it;
        packed(i, write);
    }
    return write;
}

// What gather(i, out) pushes into `out` for each triangle i (or each row of blocks i), by 64
// slices of them on every thread: each slice's items in triangle order, so that reading the
// slices one after the other reads them in the order of one pass.
template <class T, class Gather>
std::vector<std::vector<T>> gather_by_slices(std::size_t nt, const Gather& gather) {
    constexpr std::size_t kSlices = 64;
    std::vector<std::vector<T>> out(kSlices);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, kSlices, 1), [&](const auto& r) {
        for (std::size_t sl = r.begin(); sl < r.end(); ++sl)
            for (std::size_t i = nt * sl / kSlices; i < nt * (sl + 1) / kSlices; ++i)
                gather(i, out[sl]);
    });
    return out;
}

}  // namespace terrain::detail
