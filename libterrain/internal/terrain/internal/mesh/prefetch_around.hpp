#pragma once
// Private: asks early for the memory a walk will read at a vertex's neighbours, for a walk
// that goes from vertex to vertex in an order scattered over the surface (the flooding by
// cost of segment::divide_absorbed): each step would otherwise wait on a cache miss for the
// vertex and then on more for the rows above and below it. Called for the vertex a step
// ahead; only a hint (an index out of range is not fetched). Not installed.

#include <cstddef>
#include <vector>

#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::detail {

// Fetches entry v of each per-vertex array given, and on a grid adjacency the entries a row
// above and below (where a vertex's neighbours lie), with v's direction bits.
template <class... Arrays>
inline void prefetch_around(const TriangleMesh& mesh, std::size_t v, const Arrays&... arrays) {
    const auto fetch = [&](std::size_t i) {
        ((i < arrays.size() ? __builtin_prefetch(arrays.data() + i) : void()), ...);
    };
    fetch(v);
    if (!mesh.grid_adjacency()) {
        if (v + 1 < mesh.neighbor_offsets.size())
            __builtin_prefetch(mesh.neighbors.data() + mesh.neighbor_offsets[v]);
        return;
    }
    if (v < mesh.neighbor_directions.size()) __builtin_prefetch(&mesh.neighbor_directions[v]);
    const std::size_t row = mesh.grid_width;
    if (v >= row) fetch(v - row);
    fetch(v + row);
}

}  // namespace terrain::detail
