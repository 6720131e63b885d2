#pragma once
// Private: the flooding of segment::divide_absorbed (step 3, divide_absorbed.cpp): the vertices
// without a region join one along the cheapest paths from the regions' edges. In order (one
// offer at a time, Dijkstra's), or in parts of the vertices on the threads, each part flooded
// on its own and offers across parts exchanged until none improves a vertex: the same
// regions and costs (flood_in_parts says why), the serial in-order flooding's at any thread
// count and any number of parts.

#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "terrain/core/progress.hpp"
#include "terrain/internal/core/indices.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::segment::internal {

// An offer of `label` to `vertex` at path cost `cost`. Taken in order of (cost, vertex): costs
// are never negative, so their bits order as the costs do. Offers of equal cost and vertex
// differ by label; only the latest (the lowest label) is still the vertex's offer when taken,
// so their order does not matter.
struct Step {
    float cost;
    detail::i32 vertex;
    std::uint32_t label;
    std::uint64_t key() const {
        return std::uint64_t{std::bit_cast<std::uint32_t>(cost)} << 32 |
               static_cast<std::uint32_t>(vertex);
    }
};

// A vertex's state while the regions are divided, one 64-bit word: its path cost's bits in the
// high half (for a vertex without a region, its best offer's so far) and its region in the low
// half, with kFinal once the region is final (before that the region of its best offer, 0 for
// none). Costs are never negative, so the bits of two costs order as the costs do, and of two
// offers to a vertex the better one (lower cost, then lower region) is the lesser word.
using Site = std::uint64_t;
inline constexpr std::uint32_t kFinal = 0x80000000u;

inline Site site_of(float cost, std::uint32_t label) {
    return std::uint64_t{std::bit_cast<std::uint32_t>(cost)} << 32 | label;
}
inline float cost_of(Site s) {
    return std::bit_cast<float>(static_cast<std::uint32_t>(s >> 32));
}
inline std::uint32_t label_of(Site s) {
    return static_cast<std::uint32_t>(s);
}
inline std::uint32_t region_of(Site s) {
    return label_of(s) & ~kFinal;
}
inline bool is_final(Site s) {
    return (s & kFinal) != 0;
}

// The length of the edge from a to b, in the mesh's units.
double edge_length(const TriangleMesh& mesh, std::size_t a, std::size_t b);

// The edges' mean length. The costs, hence the labels, depend on the sum's last bits: it is
// taken in vertex order, on one thread, over the lengths that a wave of blocks of vertices has
// made on every thread. Progress `from` to `to` of "divide".
double mean_edge_length(const TriangleMesh& mesh, const ProgressFn& progress, double from,
                        double to);

// The costs of the offers: a path into region r costs, at each vertex u it crosses,
// |field(u) - mean(r)| plus `step` per mean edge length, summed in floats in this order.
class Flooding {
  public:
    Flooding(const TriangleMesh& mesh, const std::vector<float>& field, std::vector<Site>& sites,
             const std::vector<float>& mean, float step, double mean_edge)
        : mesh_(mesh),
          field_(field),
          sites_(sites),
          mean_(mean),
          step_(step),
          mean_edge_(mean_edge) {}

    const TriangleMesh& mesh() const { return mesh_; }
    std::vector<Site>& sites() const { return sites_; }

    // The offer from w, in a region at `at`, to its neighbour u.
    float offer(std::size_t w, Site at, std::size_t u) const {
        return cost_of(at) + std::fabs(field_[u] - mean_[region_of(at)]) + step(u, w);
    }
    // The constant part of a step from w to u: at least this is added to any offer's cost
    // (in floats, not less: a sum of floats does not fall when a term grows).
    float step(std::size_t u, std::size_t w) const {
        return step_ * static_cast<float>(edge_length(mesh_, u, w) / mean_edge_);
    }

    void prefetch(std::size_t vertex) const;

  private:
    const TriangleMesh& mesh_;
    const std::vector<float>& field_;
    std::vector<Site>& sites_;
    const std::vector<float>& mean_;
    float step_;
    double mean_edge_;
};

// The flooding one offer at a time, cheapest (then lowest vertex) first: every site not final
// with a path from a final one ends final. Progress 0 to 1, by the `to_label` vertices.
void flood_in_order(const Flooding& flooding, std::size_t to_label, const ProgressFn& progress);

// The same flooding in `parts` parts of consecutive vertices (about equal), each with its own
// queue, on the threads, in rounds: in a round each part takes, in order, the offers of its
// own that no offer still to come from another part can undercut (cheaper than the least
// offer any neighbouring part can still make: its cheapest waiting offer plus the least step
// over an edge between the two), and the offers across parts are handed over between rounds.
// Every offer taken is thus final when taken, as in flood_in_order, so every vertex gets the
// same region and cost. A round in which no part can take anything takes the least offer of
// all, as flood_in_order would next.
void flood_in_parts(const Flooding& flooding, std::size_t parts, std::size_t to_label,
                    const ProgressFn& progress);

}  // namespace terrain::segment::internal
