// Half-edges from the mesh's sorted adjacency: each directed edge a -> b is a slot of a's
// neighbour list (a's first slot plus b's rank there), so twins meet at the slots (a, b) and
// (b, a) without a hash table. The same
// slot used twice means the mesh is not a consistently oriented 2-manifold: the sweep needs
// one (it rotates around vertices and crosses edges), so that is an error here.

#include "half_edges.hpp"

#include <algorithm>
#include <string>

#include "terrain/core/error.hpp"

namespace terrain::reeb::internal {

using detail::idx;
using detail::kNone;

HalfEdges build_half_edges(const TriangleMesh& mesh) {
    const auto first = first_edge_slots(mesh);
    auto slot = [&](i32 a, i32 b) -> i32 {
        const auto nb = mesh.neighbors_of(idx(a));
        const auto it = std::lower_bound(nb.begin(), nb.end(), b);
        return (it != nb.end() && *it == b)
                   ? static_cast<i32>(first[idx(a)] + std::uint32_t(it - nb.begin()))
                   : kNone;
    };
    HalfEdges he;
    const std::size_t n_he = mesh.triangle_count() * 3;
    std::vector<i32> at_slot(first.back(), kNone);
    he.twin.assign(n_he, kNone);
    for (std::size_t h = 0; h < n_he; ++h) {
        const auto& tri = mesh.triangles()[h / 3];
        const i32 a = tri[h % 3], b = tri[(h + 1) % 3];
        const i32 s = slot(a, b);
        if (s == kNone) throw Error("reeb", "the mesh adjacency does not match its triangles");
        if (at_slot[idx(s)] != kNone)
            throw Error("reeb", "edge " + std::to_string(a) + "-" + std::to_string(b) +
                                    " is used twice in the same direction (non-manifold or "
                                    "inconsistently oriented mesh)");
        at_slot[idx(s)] = static_cast<i32>(h);
    }
    he.vertex_out.assign(mesh.vertex_count(), kNone);
    for (std::size_t h = 0; h < n_he; ++h) {
        const auto& tri = mesh.triangles()[h / 3];
        const i32 a = tri[h % 3], b = tri[(h + 1) % 3];
        const i32 t = at_slot[idx(slot(b, a))];
        he.twin[h] = t;
        if (t == kNone || he.vertex_out[idx(a)] == kNone)
            he.vertex_out[idx(a)] = static_cast<i32>(h);
    }
    // A boundary vertex must start at its boundary half-edge: prefer it over interior ones.
    for (std::size_t h = 0; h < n_he; ++h)
        if (he.twin[h] == kNone)
            he.vertex_out[idx(mesh.triangles()[h / 3][h % 3])] = static_cast<i32>(h);
    return he;
}

}  // namespace terrain::reeb::internal
