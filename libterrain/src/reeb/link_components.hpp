#pragma once
// Private: link components of the nodes (paper s.2.1: the lower and upper link subgraphs,
// whose numbers of components classify a node), for both construction algorithms.

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "terrain/core/progress.hpp"
#include "terrain/internal/core/disjoint_sets.hpp"
#include "terrain/internal/core/indices.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"

namespace terrain::reeb::internal {

using detail::i32;

// The numbers of connected components of a node's lower and upper links: the vertices
// around the node (not in it), joined by the edges of its star's triangles that do not touch
// it (the paper's link subgraphs).
class LinkCounter {
  public:
    // `star`: the triangles with a corner in node e (repeats allowed), by index.
    std::pair<int, int> count(const TriangleMesh& mesh, const ReebGraph& g, i32 e,
                              const std::vector<i32>& star);
    // The same from the triangles' corners.
    std::pair<int, int> count(const ReebGraph& g, i32 e,
                              const std::vector<std::array<i32, 3>>& star);

  private:
    template <class Corners>
    std::pair<int, int> count_star(const ReebGraph& g, i32 e, std::size_t size,
                                   const Corners& corners);
    std::vector<i32> verts_;
    detail::DisjointSets<i32> components_;  // over verts_
};

// Stores a node's link counts, capped at 255.
inline void set_links(ReebGraph& g, i32 e, std::pair<int, int> links) {
    g.node_lower_links[detail::idx(e)] = static_cast<std::uint8_t>(std::min(links.first, 255));
    g.node_upper_links[detail::idx(e)] = static_cast<std::uint8_t>(std::min(links.second, 255));
}

inline constexpr i32 kSeveral = -2;
// Up to two link components' representatives below and above a node: {kNone, kNone} for an
// empty link, {r, kNone} for one component, {r, s} for two, {kSeveral, ...} when the node is
// handled vertex by vertex (more components, a plateau, a vertex of very high degree).
struct LinkReps {
    std::array<i32, 2> lower, upper;
};

// Link components of every single-vertex node, in a pass over the triangles and one over the
// vertices, both in memory order. In a 2-manifold the link of a vertex is a cycle (interior)
// or a path (boundary), so a part of it has as many components as vertices minus edges,
// except the whole cycle (one). Going round an interior vertex counter-clockwise, each run of
// lower (upper) link vertices starts right after an upper (lower) one: the triangle holding
// that step names the run's first vertex, its representative. Writes the link counts of
// those nodes in `lower_links` and `upper_links` (a byte a node, sized by the caller: the
// graph's own node_lower_links and node_upper_links, whose other entries it leaves);
// `general` marks the nodes left to a LinkCounter.
// The stars of the triangles are gathered for `parts` parts of the vertices one after the
// other, a pass over the triangles each (0: one part below kPartedStars vertices, else
// three): the same results, less memory at once.
inline constexpr std::size_t kPartedStars = std::size_t{1} << 22;
std::vector<LinkReps> link_components(const TriangleMesh& mesh, const ReebGraph& g,
                                      std::vector<std::uint8_t>& lower_links,
                                      std::vector<std::uint8_t>& upper_links,
                                      std::vector<char>& general, const ProgressFn& progress = {},
                                      std::size_t parts = 0);

// The link counts of the critical nodes that link_components left (plateaus, vertices of very
// high degree), from their stars' triangles.
// `progress`: heartbeats (its fraction stays where the caller's was).
void count_general_links(const TriangleMesh& mesh, ReebGraph& g, const std::vector<char>& general,
                         const ProgressFn& progress = {});

}  // namespace terrain::reeb::internal
