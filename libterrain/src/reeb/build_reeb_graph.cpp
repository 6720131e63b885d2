// Reeb graph construction by a contour-tracking sweep (docs/reeb.md).
//
// Vertices are processed in increasing value; adjacent vertices with equal values form one
// event (one node). Between two events the level set is a set of contours, each a chain of
// "mixed" triangles (triangles with processed and unprocessed corners); every mixed triangle
// carries the id of its contour, and each contour knows the arc of the graph it is tracing.
// At an event P only the triangles around P change:
//   - regular vertex (one lower and one upper run in its link): the contour passes through,
//     the new triangles take its id, the node joins its arc; O(degree);
//   - otherwise the upper triangles around P form segments; segments are joined into new
//     contours by walking the old contours between their ends, all walks in lockstep, and
//     stopping as soon as the remaining ends are determined by counting (pairs left on a
//     closed contour, ends left for the boundary). Only the walked triangles are relabelled;
//     the contour left unwalked keeps its id (merges use union-find on contour ids).
// The contours entering P end their arcs at P when P is critical, and each new contour starts
// an arc at P.

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <memory>
#include <numeric>
#include <string>
#include <utility>

#include "../core/indices.hpp"
#include "../core/release.hpp"
#include "terrain/core/error.hpp"
#include "terrain/reeb/reeb_graph.hpp"

namespace terrain::reeb {

const char* to_string(NodeKind kind) {
    switch (kind) {
        case NodeKind::minimum:
            return "min";
        case NodeKind::maximum:
            return "max";
        case NodeKind::saddle:
            return "saddle";
        default:
            return "regular";
    }
}

const char* to_string(LinkClass c) {
    switch (c) {
        case LinkClass::morse_minimum:
            return "morse_minimum";
        case LinkClass::degenerate_minimum:
            return "degenerate_minimum";
        case LinkClass::morse_maximum:
            return "morse_maximum";
        case LinkClass::degenerate_maximum:
            return "degenerate_maximum";
        case LinkClass::morse_saddle:
            return "morse_saddle";
        case LinkClass::degenerate_saddle:
            return "degenerate_saddle";
        case LinkClass::asymmetric_saddle:
            return "asymmetric_saddle";
        default:
            return "regular";
    }
}

LinkClass classify_link(int lower, int upper) {
    if (upper == 0) return lower <= 1 ? LinkClass::morse_maximum : LinkClass::degenerate_maximum;
    if (lower == 0) return upper == 1 ? LinkClass::morse_minimum : LinkClass::degenerate_minimum;
    if (lower == upper)
        return lower == 1   ? LinkClass::regular
               : lower == 2 ? LinkClass::morse_saddle
                            : LinkClass::degenerate_saddle;
    return LinkClass::asymmetric_saddle;
}

std::size_t ReebGraph::memory_bytes() const {
    auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
    return bytes(node_values) + bytes(node_kinds) + bytes(node_lower_links) +
           bytes(node_upper_links) + bytes(node_vertex_offsets) + bytes(node_vertices) +
           bytes(vertex_nodes) + bytes(node_arcs) + bytes(arcs) + bytes(arc_offsets) +
           bytes(arc_nodes);
}

NodeArcs node_arcs(const ReebGraph& g) {
    NodeArcs out;
    out.offsets.assign(g.node_count() + 1, 0);
    for (const auto& a : g.arcs) {
        ++out.offsets[static_cast<std::size_t>(a[0]) + 1];
        ++out.offsets[static_cast<std::size_t>(a[1]) + 1];
    }
    std::partial_sum(out.offsets.begin(), out.offsets.end(), out.offsets.begin());
    out.arcs.resize(static_cast<std::size_t>(out.offsets.back()));
    std::vector<std::int32_t> fill(out.offsets.begin(), out.offsets.end() - 1);
    for (std::size_t a = 0; a < g.arcs.size(); ++a)
        for (int end = 0; end < 2; ++end)
            out.arcs[static_cast<std::size_t>(fill[static_cast<std::size_t>(g.arcs[a][end])]++)] =
                static_cast<std::int32_t>(a);
    return out;
}

ReebSummary summarize(const ReebGraph& g) {
    ReebSummary s;
    s.nodes = g.node_count();
    s.arcs = g.arc_count();
    std::vector<std::int32_t> parent(g.node_count());
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](std::int32_t x) {
        while (parent[static_cast<std::size_t>(x)] != x)
            x = parent[static_cast<std::size_t>(x)] =
                parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
        return x;
    };
    for (const auto& a : g.arcs) parent[static_cast<std::size_t>(find(a[0]))] = find(a[1]);
    for (std::size_t n = 0; n < g.node_count(); ++n) {
        const NodeKind k = g.node_kinds[n];
        if (k == NodeKind::regular) continue;
        ++s.critical;
        if (k == NodeKind::minimum) ++s.minima;
        if (k == NodeKind::maximum) ++s.maxima;
        if (k == NodeKind::saddle) ++s.saddles;
        if (find(static_cast<std::int32_t>(n)) == static_cast<std::int32_t>(n)) ++s.components;
        const int lo = g.node_lower_links[n], up = g.node_upper_links[n];
        s.index_sum += (lo == 0 || up == 0) ? 1.0 : 1.0 - 0.5 * (lo + up);
    }
    s.loops = s.arcs + s.components - s.critical;
    return s;
}

std::string check_reeb_graph(const ReebGraph& g, const std::vector<float>& field) {
    const std::size_t n_nodes = g.node_count();
    if (g.vertex_nodes.size() != field.size()) return "vertex_nodes has the wrong size";
    std::vector<char> seen(field.size(), 0);
    for (std::size_t n = 0; n < n_nodes; ++n) {
        const auto b = g.node_vertex_offsets[n], e = g.node_vertex_offsets[n + 1];
        if (b >= e) return "node " + std::to_string(n) + " has no vertex";
        for (auto i = b; i < e; ++i) {
            const auto v = static_cast<std::size_t>(g.node_vertices[static_cast<std::size_t>(i)]);
            if (seen[v]++) return "vertex " + std::to_string(v) + " is in two nodes";
            if (g.vertex_nodes[v] != static_cast<std::int32_t>(n))
                return "vertex " + std::to_string(v) + " maps to the wrong node";
            if (field[v] != g.node_values[n])
                return "vertex " + std::to_string(v) + " differs from its node's value";
        }
    }
    for (std::size_t v = 0; v < seen.size(); ++v)
        if (!seen[v]) return "vertex " + std::to_string(v) + " is in no node";
    std::vector<int> down(n_nodes, 0), up(n_nodes, 0);
    std::vector<char> placed(n_nodes, 0);
    for (std::size_t a = 0; a < g.arc_count(); ++a) {
        const auto [lo, hi] = g.arcs[a];
        if (!g.is_critical(lo) || !g.is_critical(hi))
            return "arc " + std::to_string(a) + " ends at a regular node";
        if (lo == hi) return "arc " + std::to_string(a) + " is a self-loop";
        ++up[static_cast<std::size_t>(lo)];
        ++down[static_cast<std::size_t>(hi)];
        float prev = g.node_values[static_cast<std::size_t>(lo)];
        for (auto i = g.arc_offsets[a]; i < g.arc_offsets[a + 1]; ++i) {
            const auto r = static_cast<std::size_t>(g.arc_nodes[static_cast<std::size_t>(i)]);
            if (g.is_critical(static_cast<std::int32_t>(r)) ||
                g.node_arcs[r] != static_cast<std::int32_t>(a) || placed[r]++)
                return "arc " + std::to_string(a) + " lists node " + std::to_string(r) + " wrongly";
            if (g.node_values[r] < prev)
                return "arc " + std::to_string(a) + " is not sorted by value";
            prev = g.node_values[r];
        }
        if (g.node_values[static_cast<std::size_t>(hi)] < prev)
            return "arc " + std::to_string(a) + " goes downwards";
    }
    for (std::size_t n = 0; n < n_nodes; ++n) {
        const NodeKind k = g.node_kinds[n];
        const bool ok = k == NodeKind::regular   ? (placed[n] && !down[n] && !up[n])
                        : k == NodeKind::minimum ? (down[n] == 0)
                        : k == NodeKind::maximum
                            ? (up[n] == 0 && down[n] > 0)
                            : (down[n] > 0 && up[n] > 0 && down[n] + up[n] >= 3);
        if (!ok) return "node " + std::to_string(n) + " (" + to_string(k) + ") has wrong arcs";
    }
    return {};
}

namespace {

using detail::i32;
using detail::kNone;
using detail::z;

// Half-edge h = 3*t + k runs from corner k of triangle t to corner (k+1)%3.
inline i32 next_he(i32 h) {
    return h % 3 == 2 ? h - 2 : h + 1;
}
inline i32 prev_he(i32 h) {
    return h % 3 == 0 ? h + 2 : h - 1;
}

struct Topology {
    std::vector<i32> twin;        // opposite half-edge, kNone on the boundary
    std::vector<i32> vertex_out;  // a half-edge leaving each vertex; on the boundary, the one
                                  // with no twin, so that rotating covers the whole fan
};

Topology build_topology(const TriangleMesh& mesh) {
    const auto& off = mesh.neighbor_offsets;
    const auto& nb = mesh.neighbors;
    auto slot = [&](i32 a, i32 b) -> i32 {
        const auto first = nb.begin() + off[z(a)], last = nb.begin() + off[z(a) + 1];
        const auto it = std::lower_bound(first, last, b);
        return (it != last && *it == b) ? static_cast<i32>(it - nb.begin()) : kNone;
    };
    Topology topo;
    const std::size_t n_he = mesh.triangle_count() * 3;
    std::vector<i32> at_slot(nb.size(), kNone);
    topo.twin.assign(n_he, kNone);
    for (std::size_t h = 0; h < n_he; ++h) {
        const auto& tri = mesh.triangles[h / 3];
        const i32 a = tri[h % 3], b = tri[(h + 1) % 3];
        const i32 s = slot(a, b);
        if (s == kNone) throw Error("reeb", "the mesh adjacency does not match its triangles");
        if (at_slot[z(s)] != kNone)
            throw Error("reeb", "edge " + std::to_string(a) + "-" + std::to_string(b) +
                                    " is used twice in the same direction (non-manifold or "
                                    "inconsistently oriented mesh)");
        at_slot[z(s)] = static_cast<i32>(h);
    }
    topo.vertex_out.assign(mesh.vertex_count(), kNone);
    for (std::size_t h = 0; h < n_he; ++h) {
        const auto& tri = mesh.triangles[h / 3];
        const i32 a = tri[h % 3], b = tri[(h + 1) % 3];
        const i32 t = at_slot[z(slot(b, a))];
        topo.twin[h] = t;
        if (t == kNone || topo.vertex_out[z(a)] == kNone)
            topo.vertex_out[z(a)] = static_cast<i32>(h);
    }
    // A boundary vertex must start at its boundary half-edge: prefer it over interior ones.
    for (std::size_t h = 0; h < n_he; ++h)
        if (topo.twin[h] == kNone)
            topo.vertex_out[z(mesh.triangles[h / 3][h % 3])] = static_cast<i32>(h);
    return topo;
}

// Sort key of a float: monotonic unsigned bits (-0 taken as +0).
inline std::uint32_t float_key(float f) {
    if (f == 0.0f) f = 0.0f;
    const auto u = std::bit_cast<std::uint32_t>(f);
    return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

// The float of a sort key (-0 comes back as +0).
inline float key_float(std::uint32_t k) {
    return std::bit_cast<float>((k & 0x80000000u) ? (k & 0x7fffffffu) : ~k);
}

// Sorts the vertices into events (nodes) in increasing value: adjacent vertices with equal
// values form one event; other ties go by the plateau's lowest vertex, then by vertex. Fills
// the graph's node_vertex_offsets, node_vertices and vertex_nodes.
void order_events(const TriangleMesh& mesh, const std::vector<float>& field, ReebGraph& g) {
    const std::size_t nv = field.size();
    // Stable LSD radix sort of (value bits << 32 | vertex) on the value bits, 11 bits per
    // pass: ties keep vertex order.
    std::vector<std::uint64_t> keys(nv), tmp(nv);
    for (std::size_t v = 0; v < nv; ++v) keys[v] = (std::uint64_t{float_key(field[v])} << 32) | v;
    constexpr int kBits = 11;
    constexpr std::size_t kBuckets = std::size_t{1} << kBits;
    std::vector<std::uint32_t> count(3 * kBuckets, 0u);
    for (const std::uint64_t k : keys)
        for (int p = 0; p < 3; ++p)
            ++count[z(p) * kBuckets + ((k >> (32 + kBits * p)) & (kBuckets - 1))];
    for (int p = 0; p < 3; ++p) {
        std::uint32_t* c = count.data() + z(p) * kBuckets;
        const int shift = 32 + kBits * p;
        if (nv == 0 || c[(keys[0] >> shift) & (kBuckets - 1)] == nv) continue;  // one bucket
        std::uint32_t sum = 0;
        for (std::size_t b = 0; b < kBuckets; ++b) sum += std::exchange(c[b], sum);
        for (const std::uint64_t k : keys) tmp[c[(k >> shift) & (kBuckets - 1)]++] = k;
        keys.swap(tmp);
    }
    detail::release(tmp);
    auto same_value = [](std::uint64_t a, std::uint64_t b) { return (a >> 32) == (b >> 32); };
    auto vertex = [](std::uint64_t k) { return static_cast<i32>(k & 0xffffffffu); };
    // Plateaus: adjacent vertices of equal value. Only a vertex whose value another vertex
    // shares (next to it in the sorted order) can be in one; in a noisy field that is rare.
    std::vector<char> tied;
    for (std::size_t i = 1; i < nv; ++i)
        if (same_value(keys[i], keys[i - 1])) {
            if (tied.empty()) tied.assign(nv, 0);
            tied[z(vertex(keys[i]))] = tied[z(vertex(keys[i - 1]))] = 1;
        }
    std::vector<i32> rep;  // each vertex's plateau representative (its lowest vertex)
    auto root = [&](i32 x) {
        while (rep[z(x)] != x) x = rep[z(x)] = rep[z(rep[z(x)])];
        return x;
    };
    for (std::size_t v = 0; v < tied.size(); ++v) {
        if (!tied[v]) continue;
        for (auto i = mesh.neighbor_offsets[v]; i < mesh.neighbor_offsets[v + 1]; ++i) {
            const i32 w = mesh.neighbors[z(i)];
            if (z(w) > v && field[z(w)] == field[v]) {
                if (rep.empty()) {
                    rep.resize(nv);
                    std::iota(rep.begin(), rep.end(), 0);
                }
                const i32 a = root(static_cast<i32>(v)), b = root(w);
                if (a != b) rep[z(std::max(a, b))] = std::min(a, b);
            }
        }
    }
    detail::release(tied);
    const bool any_plateau = !rep.empty();
    if (any_plateau) {
        for (std::size_t v = 0; v < nv; ++v) rep[v] = root(static_cast<i32>(v));
        // Equal values: plateaus together, ordered by their lowest vertex.
        for (std::size_t i = 0; i < nv;) {
            std::size_t j = i + 1;
            while (j < nv && same_value(keys[i], keys[j])) ++j;
            if (j - i > 1)
                std::sort(keys.begin() + static_cast<std::ptrdiff_t>(i),
                          keys.begin() + static_cast<std::ptrdiff_t>(j),
                          [&](std::uint64_t a, std::uint64_t b) {
                              const i32 ra = rep[z(vertex(a))], rb = rep[z(vertex(b))];
                              return ra != rb ? ra < rb : vertex(a) < vertex(b);
                          });
            i = j;
        }
    }
    auto same_event = [&](std::uint64_t a, std::uint64_t b) {
        return any_plateau && same_value(a, b) && rep[z(vertex(a))] == rep[z(vertex(b))];
    };
    g.node_vertices.resize(nv);
    g.vertex_nodes.resize(nv);
    g.node_vertex_offsets.clear();
    g.node_values.clear();
    std::size_t n_nodes = nv;
    if (any_plateau) {
        n_nodes = 0;
        for (std::size_t i = 0; i < nv; ++i) n_nodes += i == 0 || !same_event(keys[i], keys[i - 1]);
    }
    g.node_vertex_offsets.reserve(n_nodes + 1);
    g.node_values.reserve(n_nodes);
    constexpr std::size_t kAhead = 16;  // vertex_nodes is written in random order
    for (std::size_t i = 0; i < nv; ++i) {
        if (i + kAhead < nv) __builtin_prefetch(&g.vertex_nodes[z(vertex(keys[i + kAhead]))], 1);
        const i32 v = vertex(keys[i]);
        if (i == 0 || !same_event(keys[i], keys[i - 1])) {
            g.node_vertex_offsets.push_back(static_cast<i32>(i));
            g.node_values.push_back(key_float(static_cast<std::uint32_t>(keys[i] >> 32)));
        }
        g.node_vertices[i] = v;
        g.vertex_nodes[z(v)] = static_cast<i32>(g.node_vertex_offsets.size() - 1);
    }
    g.node_vertex_offsets.push_back(static_cast<i32>(nv));
}

// True when the Reeb graph of any field on the mesh is a tree: every connected component is
// of genus 0 with at most one boundary loop (a disk or a sphere). Assumes a 2-manifold.
bool loop_free(const TriangleMesh& mesh) {
    // A component's Euler characteristic is 2 - 2g - b: it is 1 or 2 exactly when the
    // component is a disk (g = 0, b = 1) or a sphere (g = 0, b = 0).
    const std::size_t nv = mesh.vertex_count();
    std::vector<i32> comp(nv);
    std::iota(comp.begin(), comp.end(), 0);
    auto root = [&](i32 x) {
        while (comp[z(x)] != x) x = comp[z(x)] = comp[z(comp[z(x)])];
        return x;
    };
    for (const auto& t : mesh.triangles)
        for (int k = 0; k < 2; ++k) {
            const i32 a = root(t[z(k)]), b = root(t[z(k + 1)]);
            if (a != b) comp[z(std::max(a, b))] = std::min(a, b);
        }
    std::vector<std::int64_t> chi(nv, 0);
    for (std::size_t v = 0; v < nv; ++v) {
        std::int64_t upper_neighbours = 0;
        for (i32 i = mesh.neighbor_offsets[v]; i < mesh.neighbor_offsets[v + 1]; ++i)
            upper_neighbours += z(mesh.neighbors[z(i)]) > v;
        chi[z(root(static_cast<i32>(v)))] += 1 - upper_neighbours;
    }
    for (const auto& t : mesh.triangles) chi[z(root(t[0]))] += 1;
    for (std::size_t v = 0; v < nv; ++v)
        if (comp[v] == static_cast<i32>(v) && chi[v] != 1 && chi[v] != 2) return false;
    return true;
}

// The numbers of connected components of a node's lower and upper links: the vertices
// around the node (not in it), joined by the edges of its star's triangles that do not touch
// it (the paper's link subgraphs).
class LinkCounter {
  public:
    // `star`: the triangles with a corner in node e (repeats allowed).
    std::pair<int, int> count(const TriangleMesh& mesh, const ReebGraph& g, i32 e,
                              const std::vector<i32>& star) {
        verts_.clear();
        for (const i32 t : star)
            for (const i32 c : mesh.triangles[z(t)])
                if (g.vertex_nodes[z(c)] != e) verts_.push_back(c);
        std::sort(verts_.begin(), verts_.end());
        verts_.erase(std::unique(verts_.begin(), verts_.end()), verts_.end());
        parent_.resize(verts_.size());
        std::iota(parent_.begin(), parent_.end(), 0);
        auto index = [&](i32 v) {
            return static_cast<i32>(std::lower_bound(verts_.begin(), verts_.end(), v) -
                                    verts_.begin());
        };
        auto find = [&](i32 x) {
            while (parent_[z(x)] != x) x = parent_[z(x)] = parent_[z(parent_[z(x)])];
            return x;
        };
        for (const i32 t : star) {
            const auto& tri = mesh.triangles[z(t)];
            for (int j = 0; j < 3; ++j) {
                const i32 a = tri[z(j)], b = tri[z((j + 1) % 3)];
                const i32 na = g.vertex_nodes[z(a)], nb = g.vertex_nodes[z(b)];
                if (na == e || nb == e || (na < e) != (nb < e)) continue;
                const i32 ra = find(index(a)), rb = find(index(b));
                if (ra != rb) parent_[z(ra)] = rb;
            }
        }
        int lower = 0, upper = 0;
        for (std::size_t i = 0; i < verts_.size(); ++i)
            if (find(static_cast<i32>(i)) == static_cast<i32>(i))
                ++(g.vertex_nodes[z(verts_[i])] < e ? lower : upper);
        return {lower, upper};
    }

  private:
    std::vector<i32> verts_, parent_;
};

void set_links(ReebGraph& g, i32 e, std::pair<int, int> links) {
    g.node_lower_links[z(e)] = static_cast<std::uint8_t>(std::min(links.first, 255));
    g.node_upper_links[z(e)] = static_cast<std::uint8_t>(std::min(links.second, 255));
}

constexpr i32 kSeveral = -2;
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
// that step names the run's first vertex, its representative. Gives the link counts of those
// vertices in `vertex_links`; `general` marks the nodes left to a LinkCounter.
using LinkCounts = std::array<std::uint8_t, 2>;
std::vector<LinkReps> link_components(const TriangleMesh& mesh, const ReebGraph& g,
                                      std::vector<LinkCounts>& vertex_links,
                                      std::vector<char>& general) {
    const std::size_t nv = mesh.vertex_count(), nn = g.node_count();
    const auto& node = g.vertex_nodes;
    // starts[0..1]: lower runs' first vertices, starts[2..3]: upper runs'; runs[0], runs[1]:
    // how many lower and upper runs were seen.
    struct Star {
        std::array<i32, 4> starts;
        std::uint8_t triangles, lower_edges, upper_edges;
        std::array<std::uint8_t, 2> runs;
    };
    std::vector<Star> stars(nv, Star{{kNone, kNone, kNone, kNone}, 0, 0, 0, {0, 0}});
    for (const auto& t : mesh.triangles) {
        const std::array<i32, 3> n{node[z(t[0])], node[z(t[1])], node[z(t[2])]};
        for (const i32 c : t) ++stars[z(c)].triangles;
        if (n[0] != n[1] && n[1] != n[2] && n[0] != n[2]) {
            // The highest corner sees a lower link edge, the lowest an upper one; going round
            // the middle corner counter-clockwise, the step a -> b crosses its value: b starts
            // a lower run when a is above, an upper run when a is below. No branches: the
            // orders are unpredictable.
            const int hi = n[0] > n[1] ? (n[0] > n[2] ? 0 : 2) : (n[1] > n[2] ? 1 : 2);
            const int lo = n[0] < n[1] ? (n[0] < n[2] ? 0 : 2) : (n[1] < n[2] ? 1 : 2);
            const int mid = 3 - hi - lo, a = mid == 2 ? 0 : mid + 1, b = 3 - mid - a;
            ++stars[z(t[z(hi)])].lower_edges;
            ++stars[z(t[z(lo)])].upper_edges;
            Star& s = stars[z(t[z(mid)])];
            const int side = n[z(a)] > n[z(mid)] ? 0 : 1;
            s.starts[z(2 * side + (s.runs[z(side)] & 1))] = n[z(b)];
            ++s.runs[z(side)];
            continue;
        }
        // Two corners in one node (a plateau): the third sees an edge of its lower or upper
        // link; the plateau's corners see an edge touching their node, which does not count.
        for (int k = 0; k < 3; ++k) {
            const i32 m = n[z(k)], p = n[z((k + 1) % 3)], q = n[z((k + 2) % 3)];
            stars[z(t[z(k)])].lower_edges += (m > p) & (m > q);
            stars[z(t[z(k)])].upper_edges += (m < p) & (m < q);
        }
    }
    std::vector<LinkReps> reps(nn);
    general.assign(nn, 0);
    vertex_links.resize(nv);
    constexpr std::size_t kAhead = 16;  // the nodes' entries are written in random order
    for (std::size_t v = 0; v < nv; ++v) {
        if (v + kAhead < nv) __builtin_prefetch(&reps[z(node[v + kAhead])], 1);
        const i32 n = node[v];
        const i32 b = mesh.neighbor_offsets[v], e = mesh.neighbor_offsets[v + 1];
        int below = 0, same = 0;
        i32 some_below = kNone, some_above = kNone;
        for (i32 i = b; i < e; ++i) {
            const i32 m = node[z(mesh.neighbors[z(i)])];
            below += m < n;
            same += m == n;  // a plateau
            some_below = m < n ? m : some_below;
            some_above = m < n ? some_above : m;
        }
        if (e - b > 250 || same > 0) {
            general[z(n)] = 1;
            reps[z(n)] = {{kSeveral, kNone}, {kSeveral, kNone}};
            continue;
        }
        const int above = e - b - below;
        const Star& s = stars[v];
        const bool interior = s.triangles == e - b;
        const int lower = (above == 0 && interior && below > 0) ? 1 : below - s.lower_edges;
        const int upper = (below == 0 && interior && above > 0) ? 1 : above - s.upper_edges;
        vertex_links[v] = {static_cast<std::uint8_t>(lower), static_cast<std::uint8_t>(upper)};
        auto side = [&](int count, i32 some, int runs, const std::array<i32, 2>& starts) {
            if (count <= 1) return std::array<i32, 2>{count == 0 ? kNone : some, kNone};
            if (count == 2 && runs == 2) return starts;
            return std::array<i32, 2>{kSeveral, kNone};
        };
        reps[z(n)] = {side(lower, some_below, s.runs[0], {s.starts[0], s.starts[1]}),
                      side(upper, some_above, s.runs[1], {s.starts[2], s.starts[3]})};
    }
    return reps;
}

// The link counts of the critical nodes that link_components left (plateaus, vertices of very
// high degree), from their stars' triangles.
void count_general_links(const TriangleMesh& mesh, ReebGraph& g, const std::vector<char>& general) {
    std::vector<char> wanted;  // per vertex
    for (std::size_t n = 0; n < g.node_count(); ++n) {
        if (!general[n] || g.node_kinds[n] == NodeKind::regular) continue;
        if (wanted.empty()) wanted.assign(mesh.vertex_count(), 0);
        for (i32 i = g.node_vertex_offsets[n]; i < g.node_vertex_offsets[n + 1]; ++i)
            wanted[z(g.node_vertices[z(i)])] = 1;
    }
    if (wanted.empty()) return;
    std::vector<std::pair<i32, i32>> star;  // (node, triangle)
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t)
        for (const i32 c : mesh.triangles[t])
            if (wanted[z(c)]) star.push_back({g.vertex_nodes[z(c)], static_cast<i32>(t)});
    std::sort(star.begin(), star.end());
    LinkCounter counter;
    std::vector<i32> tris;
    for (std::size_t i = 0; i < star.size();) {
        const i32 n = star[i].first;
        tris.clear();
        for (; i < star.size() && star[i].first == n; ++i) tris.push_back(star[i].second);
        set_links(g, n, counter.count(mesh, g, n, tris));
    }
}

// The contour tree of a loop-free mesh (Carr, Snoeyink & Axen): join and split trees by
// union-find sweeps over the events, merged leaf by leaf into the augmented contour tree,
// whose chains of regular nodes become the arcs. Returns false, leaving the graph half made,
// when the mesh has handles or holes: the join tree gives its components, and a single
// component's Euler characteristic is V - E + F.
bool contour_tree(const TriangleMesh& mesh, ReebGraph& g, const ProgressFn& progress) {
    const std::size_t nn = g.node_count();
    g.node_lower_links.assign(nn, 1);
    g.node_upper_links.assign(nn, 1);
    std::vector<char> general;
    std::vector<LinkCounts> vertex_links;
    const std::vector<LinkReps> reps = link_components(mesh, g, vertex_links, general);
    report_progress(progress, 0.3, "reeb: links");

    std::vector<i32> jp(nn, kNone), sp(nn, kNone);
    // Children in the join and split trees. The sweeps run in opposite directions, so they
    // share cache lines only where they cross.
    std::vector<std::array<i32, 2>> kids(nn);
    // One union-find sweep. A node's entry holds its parent, or (at a root) minus one minus its
    // rank, and the last event added to its component (the component's head). Most events have
    // one link component below (above): one find, and the event hangs under the root. The join
    // (ascending) and split (descending) sweeps are independent and run side by side.
    struct Entry {
        i32 up, head;
    };
    auto sweep = [&](bool ascending, std::vector<i32>& parent) {
        const std::size_t side = ascending ? 0 : 1;
        std::vector<Entry> uf(nn, Entry{-1, 0});
        auto find = [&](i32 x) {
            i32 r = x;
            while (uf[z(r)].up >= 0) r = uf[z(r)].up;
            while (x != r) {
                const i32 nx = uf[z(x)].up;
                uf[z(x)].up = r;
                x = nx;
            }
            return r;
        };
        auto reps_at = [&](std::size_t k) -> const std::array<i32, 2>& {
            const std::size_t e = ascending ? k : nn - 1 - k;
            return ascending ? reps[e].lower : reps[e].upper;
        };
        // Paths are short: two steps up without branching, then the rare longer path.
        auto find_short = [&](i32 x) {
            const i32 ux = uf[z(x)].up;
            const i32 b = ux >= 0 ? ux : x;
            const i32 ub = uf[z(b)].up;
            i32 c = ub >= 0 ? ub : b;
            if (uf[z(c)].up >= 0) [[unlikely]]
                c = find(c);
            uf[z(x)].up = ux >= 0 ? c : ux;
            return c;
        };
        // The sweep waits on memory: the entries of the representatives a few events ahead
        // are fetched early (and, from those, their parents').
        constexpr std::size_t kAhead = 16;
        auto prefetch = [&](i32 x) { __builtin_prefetch(&uf[z(x >= 0 && z(x) < nn ? x : 0)]); };
        // Component c (a root) joins the component of event e whose root is cur, by rank (the
        // higher rank has the lower `up`); returns the new root.
        auto join = [&](i32 cur, i32 c, i32 e) {
            parent[z(uf[z(c)].head)] = e;
            ++kids[z(e)][side];
            const bool cur_higher = uf[z(cur)].up <= uf[z(c)].up;
            const i32 hi = cur_higher ? cur : c, lo = cur_higher ? c : cur;
            if (uf[z(hi)].up == uf[z(lo)].up) --uf[z(hi)].up;
            uf[z(lo)].up = hi;
            uf[z(hi)].head = e;
            return hi;
        };
        std::vector<i32> roots;
        for (std::size_t k = 0; k < nn; ++k) {
            if (k + kAhead < nn) {
                const auto& r = reps_at(k + kAhead);
                prefetch(r[0]);
                prefetch(r[1]);
            }
            if (k + kAhead / 2 < nn) {
                const auto& r = reps_at(k + kAhead / 2);
                if (r[0] >= 0) prefetch(uf[z(r[0])].up);
                if (r[1] >= 0) prefetch(uf[z(r[1])].up);
            }
            const i32 e = static_cast<i32>(ascending ? k : nn - 1 - k);
            const auto& rep = reps_at(k);
            if (rep[0] >= 0) {
                // The event hangs under the component of its first link component.
                const i32 c = find_short(rep[0]);
                Entry& root = uf[z(c)];
                parent[z(root.head)] = e;
                kids[z(e)][side] = 1;
                uf[z(e)].up = c;
                root.head = e;
                root.up -= root.up == -1;  // rank 0 -> 1
                if (rep[1] < 0) continue;
                const i32 o = find_short(rep[1]);
                if (o != c) join(c, o, e);  // a second component joins here
                continue;
            }
            uf[z(e)] = {-1, e};
            kids[z(e)][side] = 0;
            if (rep[0] == kNone) continue;
            roots.clear();
            for (i32 i = g.node_vertex_offsets[z(e)]; i < g.node_vertex_offsets[z(e) + 1]; ++i) {
                const i32 v = g.node_vertices[z(i)];
                for (i32 j = mesh.neighbor_offsets[z(v)]; j < mesh.neighbor_offsets[z(v) + 1];
                     ++j) {
                    const i32 n = g.vertex_nodes[z(mesh.neighbors[z(j)])];
                    if (ascending ? n >= e : n <= e) continue;
                    const i32 c = find(n);
                    if (std::find(roots.begin(), roots.end(), c) == roots.end()) roots.push_back(c);
                }
            }
            i32 cur = e;
            for (const i32 c : roots) cur = join(cur, c, e);
        }
    };
    tbb::parallel_invoke([&] { sweep(true, jp); }, [&] { sweep(false, sp); });
    const auto components = std::count(jp.begin(), jp.end(), kNone);
    const auto chi = static_cast<std::int64_t>(mesh.vertex_count()) -
                     static_cast<std::int64_t>(mesh.neighbors.size() / 2) +
                     static_cast<std::int64_t>(mesh.triangle_count());
    if (components == 1 ? (chi != 1 && chi != 2) : !loop_free(mesh)) return false;
    report_progress(progress, 0.6, "reeb: join and split trees");

    // Merge: remove leaves one by one; each removal is one edge of the augmented tree. A
    // removed node's join-children count is set to -1; attach[x] = 2 * y + (x was below y).
    auto dead = [&](i32 x) { return kids[z(x)][0] < 0; };
    auto next_alive = [&](std::vector<i32>& parent, i32 x) {
        i32 p = parent[z(x)];
        while (p != kNone && dead(p)) p = parent[z(p)];
        for (i32 q = parent[z(x)]; q != p;) {
            const i32 nx = parent[z(q)];
            parent[z(q)] = p;
            q = nx;
        }
        parent[z(x)] = p;
        return p;
    };
    auto is_leaf = [&](i32 x) {
        const auto [j, s] = kids[z(x)];
        return (j == 0 && s == 1) || (s == 0 && j == 1);
    };
    std::vector<i32> queue, attach(nn, kNone);
    queue.reserve(nn);
    for (std::size_t n = 0; n < nn; ++n)
        if (is_leaf(static_cast<i32>(n))) queue.push_back(static_cast<i32>(n));
    constexpr std::size_t kAhead = 16;  // as in the sweeps: fetch the next leaves' entries early
    for (std::size_t qi = 0; qi < queue.size(); ++qi) {
        if (qi + kAhead < queue.size()) {
            const i32 x = queue[qi + kAhead];
            __builtin_prefetch(&kids[z(x)]);
            __builtin_prefetch(&jp[z(x)]);
            __builtin_prefetch(&sp[z(x)]);
        }
        if (qi + kAhead / 2 < queue.size()) {
            const i32 x = queue[qi + kAhead / 2];
            const i32 p = (kids[z(x)][0] == 0 ? jp : sp)[z(x)];
            __builtin_prefetch(&kids[z(p >= 0 ? p : 0)]);
        }
        const i32 x = queue[qi];
        if (dead(x) || !is_leaf(x)) continue;
        const bool lower = kids[z(x)][0] == 0;
        const i32 y = next_alive(lower ? jp : sp, x);
        if (y == kNone) throw Error("reeb", "internal error: contour tree leaf without parent");
        kids[z(x)][0] = -1;
        attach[z(x)] = 2 * y + lower;
        --kids[z(y)][lower ? 0 : 1];
        if (is_leaf(y)) queue.push_back(y);
    }
    detail::release(queue);
    detail::release(kids);
    report_progress(progress, 0.75, "reeb: contour tree");

    // Up-edges per node (CSR, in the order of the removed leaves' indices), and down degrees.
    std::vector<i32> up_off(nn + 1, 0), up_to(nn), down_deg(nn, 0);
    auto edge = [&](std::size_t x) {
        const i32 y = attach[x] >> 1, self = static_cast<i32>(x);
        return (attach[x] & 1) ? std::pair{self, y} : std::pair{y, self};
    };
    for (std::size_t x = 0; x < nn; ++x)
        if (attach[x] != kNone) {
            const auto [lo, hi] = edge(x);
            ++up_off[z(lo) + 1];
            ++down_deg[z(hi)];
        }
    std::partial_sum(up_off.begin(), up_off.end(), up_off.begin());
    {
        std::vector<i32> fill(up_off.begin(), up_off.end() - 1);
        for (std::size_t x = 0; x < nn; ++x)
            if (attach[x] != kNone) {
                const auto [lo, hi] = edge(x);
                up_to[z(fill[z(lo)]++)] = hi;
            }
    }
    g.node_kinds.assign(nn, NodeKind::regular);
    for (std::size_t n = 0; n < nn; ++n) {
        const int d = down_deg[n], u = up_off[n + 1] - up_off[n];
        if (d == 1 && u == 1) continue;  // Reeb-regular, whatever its link (links stay 1, 1)
        g.node_kinds[n] = d == 0   ? NodeKind::minimum
                          : u == 0 ? NodeKind::maximum
                                   : NodeKind::saddle;
        if (general[n]) continue;  // counted below
        const auto links = vertex_links[z(g.node_vertices[z(g.node_vertex_offsets[n])])];
        g.node_lower_links[n] = links[0];
        g.node_upper_links[n] = links[1];
    }
    detail::release(vertex_links);
    // Arcs in the order of their lower nodes, then of their up-edges. A regular node takes the
    // arc of the edge below it; `below` holds that edge as the regular node under it, or as
    // -2 - arc when the edge leaves a critical node. One pass in increasing order then fills in
    // every regular node (its lower neighbour comes first), so no chain is followed.
    auto critical = [&](i32 n) { return g.node_kinds[z(n)] != NodeKind::regular; };
    std::vector<i32>& below = attach;  // attach is no longer needed
    g.arcs.clear();
    for (std::size_t lo = 0; lo < nn; ++lo)
        for (i32 k = up_off[lo]; k < up_off[lo + 1]; ++k) {
            const i32 hi = up_to[z(k)];
            if (critical(static_cast<i32>(lo))) {
                const i32 arc = static_cast<i32>(g.arcs.size());
                g.arcs.push_back({static_cast<i32>(lo), critical(hi) ? hi : kNone});
                if (!critical(hi)) below[z(hi)] = -2 - arc;
            } else if (!critical(hi)) {
                below[z(hi)] = static_cast<i32>(lo);
            }
        }
    g.node_arcs.assign(nn, kNone);
    g.arc_offsets.assign(g.arcs.size() + 1, 0);
    for (std::size_t n = 0; n < nn; ++n) {
        if (critical(static_cast<i32>(n))) continue;
        const i32 b = below[n];
        const i32 arc = b >= 0 ? g.node_arcs[z(b)] : -2 - b;
        g.node_arcs[n] = arc;
        ++g.arc_offsets[z(arc) + 1];
        const i32 hi = up_to[z(up_off[n])];
        if (critical(hi)) g.arcs[z(arc)][1] = hi;
    }
    std::partial_sum(g.arc_offsets.begin(), g.arc_offsets.end(), g.arc_offsets.begin());
    g.arc_nodes.resize(z(g.arc_offsets.back()));
    {
        std::vector<i32> fill(g.arc_offsets.begin(), g.arc_offsets.end() - 1);
        for (std::size_t n = 0; n < nn; ++n)
            if (!critical(static_cast<i32>(n)))
                g.arc_nodes[z(fill[z(g.node_arcs[n])]++)] = static_cast<i32>(n);
    }
    report_progress(progress, 0.9, "reeb: arcs");
    count_general_links(mesh, g, general);
    return true;
}

class Sweep {
  public:
    Sweep(const TriangleMesh& mesh, const std::vector<float>& field, ReebGraph& g)
        : mesh_(mesh), field_(field), g_(g) {}

    // `ordered`: the graph's events are already set (order_events).
    void run(const ProgressFn& progress, bool ordered);

  private:
    struct Contour {
        i32 parent;
        i32 arc;
        i32 open;  // boundary ends (0 for a closed contour, 2 for a path)
    };
    struct ArcBuild {
        i32 lower, upper, head, tail, count;
    };
    struct End {
        i32 segment;  // local index of its segment's first triangle (union-find root later)
        i32 s_he;     // half-edge of the new triangle on the exit edge
        i32 label;    // old contour across the exit
        i32 cur;      // walk position: half-edge through which the current triangle was entered
        i32 partner;  // paired end
        i32 walk;     // index of its visited-triangle buffer
        std::int8_t state;  // 0 open, 1 paired, 2 boundary
        bool complete;      // the piece to its destination was walked to the end
    };

    void process_event(i32 e, i32 begin, i32 end);
    bool try_regular(i32 e, i32 v);
    void general_event(i32 e, i32 begin, i32 end);

    bool processed(i32 v, i32 e) const { return g_.vertex_nodes[z(v)] <= e; }
    bool in_event(i32 t, i32 e) const {
        const auto& tri = mesh_.triangles[z(t)];
        return g_.vertex_nodes[z(tri[0])] == e || g_.vertex_nodes[z(tri[1])] == e ||
               g_.vertex_nodes[z(tri[2])] == e;
    }
    i32 find(i32 c) {
        while (contours_[z(c)].parent != c) {
            const i32 p = contours_[z(c)].parent;
            contours_[z(c)].parent = contours_[z(p)].parent;
            c = p;
        }
        return c;
    }
    i32 new_contour(i32 arc, i32 open) {
        contours_.push_back({static_cast<i32>(contours_.size()), arc, open});
        return static_cast<i32>(contours_.size() - 1);
    }
    i32 new_arc(i32 lower) {
        arcs_.push_back({lower, kNone, kNone, kNone, 0});
        return static_cast<i32>(arcs_.size() - 1);
    }
    void append_regular(i32 arc, i32 node) {
        auto& a = arcs_[z(arc)];
        if (a.tail == kNone)
            a.head = node;
        else
            node_next_[z(a.tail)] = node;
        a.tail = node;
        ++a.count;
        g_.node_arcs[z(node)] = arc;
    }
    // One walk step from end i; returns 0 (going on), 1 (arrived at another end), 2 (boundary).
    int step(i32 i, i32 e);
    i32 end_at(i32 s_he) const;
    void deduce(i32 label);
    void finish_graph();

    const TriangleMesh& mesh_;
    const std::vector<float>& field_;
    ReebGraph& g_;
    Topology topo_;
    std::vector<i32> tri_label_;
    std::vector<Contour> contours_;
    std::vector<ArcBuild> arcs_;
    std::vector<i32> node_next_;

    // Scratch for general events, reused.
    std::vector<i32> star_, seg_parent_, seg_bnd_, d_in_;
    std::vector<End> ends_;
    std::vector<std::pair<i32, i32>> end_index_;  // (s_he, end) sorted
    std::vector<std::vector<i32>> walks_;
    struct LabelCount {
        i32 label, unresolved, need_boundary;
    };
    std::vector<LabelCount> label_counts_;
    LinkCounter links_;
};

void Sweep::run(const ProgressFn& progress, bool ordered) {
    topo_ = build_topology(mesh_);
    report_progress(progress, 0.1, "reeb: topology");
    if (!ordered) order_events(mesh_, field_, g_);
    report_progress(progress, 0.3, "reeb: order");
    const std::size_t n_nodes = g_.node_vertex_offsets.size() - 1;
    g_.node_kinds.assign(n_nodes, NodeKind::regular);
    g_.node_lower_links.assign(n_nodes, 0);
    g_.node_upper_links.assign(n_nodes, 0);
    g_.node_arcs.assign(n_nodes, kNone);
    node_next_.assign(n_nodes, kNone);
    tri_label_.assign(mesh_.triangle_count(), kNone);
    contours_.reserve(1024);
    arcs_.reserve(1024);
    const std::size_t step = std::max<std::size_t>(n_nodes / 50, 1);
    for (std::size_t e = 0; e < n_nodes; ++e) {
        const i32 b = g_.node_vertex_offsets[e], en = g_.node_vertex_offsets[e + 1];
        process_event(static_cast<i32>(e), b, en);
        if (e % step == 0)
            report_progress(progress, 0.3 + 0.65 * static_cast<double>(e) / n_nodes, "reeb");
    }
    finish_graph();
    report_progress(progress, 1.0, "reeb");
}

void Sweep::process_event(i32 e, i32 begin, i32 end) {
    if (end - begin == 1 && try_regular(e, g_.node_vertices[z(begin)])) return;
    general_event(e, begin, end);
}

// The common case: a single vertex whose link has one lower and one upper run.
bool Sweep::try_regular(i32 e, i32 v) {
    const i32 h0 = topo_.vertex_out[z(v)];
    if (h0 == kNone) return false;
    const bool boundary = topo_.twin[z(h0)] == kNone;
    // Walk the fan: for each triangle, its corner after v (the link vertex) is `a`.
    int changes = 0, lower_runs = 0, upper_runs = 0;
    i32 label_tri = kNone;
    bool first_lower = false, last_lower = false;
    i32 h = h0;
    bool first = true;
    for (;;) {
        const i32 t = h / 3;
        const i32 a = mesh_.triangles[z(t)][z((h + 1) % 3)];
        const bool lower = g_.vertex_nodes[z(a)] < e;
        if (first) {
            first_lower = lower;
            (lower ? lower_runs : upper_runs) = 1;
            first = false;
        } else if (lower != last_lower) {
            ++changes;
            ++(lower ? lower_runs : upper_runs);
        }
        last_lower = lower;
        if (label_tri == kNone && lower) label_tri = t;
        const i32 in = prev_he(h);
        const i32 tw = topo_.twin[z(in)];
        if (tw == kNone) {  // boundary: the last link vertex is the far corner of this triangle
            const i32 b = mesh_.triangles[z(t)][z((h + 2) % 3)];
            const bool bl = g_.vertex_nodes[z(b)] < e;
            if (bl != last_lower) {
                ++changes;
                ++(bl ? lower_runs : upper_runs);
            }
            if (label_tri == kNone && bl) label_tri = t;
            break;
        }
        h = tw;
        if (h == h0) break;
        if (changes > 2) return false;
    }
    if (!boundary) {
        if (first_lower != last_lower) ++changes;
        if (changes != 2) return false;
    } else if (lower_runs != 1 || upper_runs != 1) {
        return false;
    }
    const i32 c = find(tri_label_[z(label_tri)]);
    // Relabel the triangles that stay mixed (those with an upper corner).
    h = h0;
    for (;;) {
        const i32 t = h / 3;
        const auto& tri = mesh_.triangles[z(t)];
        if (g_.vertex_nodes[z(tri[0])] > e || g_.vertex_nodes[z(tri[1])] > e ||
            g_.vertex_nodes[z(tri[2])] > e)
            tri_label_[z(t)] = c;
        const i32 tw = topo_.twin[z(prev_he(h))];
        if (tw == kNone || tw == h0) break;
        h = tw;
    }
    g_.node_lower_links[z(e)] = 1;
    g_.node_upper_links[z(e)] = 1;
    append_regular(contours_[z(c)].arc, e);
    return true;
}

i32 Sweep::end_at(i32 s_he) const {
    const auto it =
        std::lower_bound(end_index_.begin(), end_index_.end(), std::make_pair(s_he, kNone));
    return (it != end_index_.end() && it->first == s_he) ? it->second : kNone;
}

int Sweep::step(i32 i, i32 e) {
    End& en = ends_[z(i)];
    const i32 t = en.cur / 3;
    const auto& tri = mesh_.triangles[z(t)];
    walks_[z(en.walk)].push_back(t);
    i32 out = kNone;
    for (i32 k = 1; k <= 2; ++k) {
        const i32 j = (en.cur % 3 + k) % 3;
        if (processed(tri[z(j)], e) != processed(tri[z((j + 1) % 3)], e)) {
            out = 3 * t + j;
            break;
        }
    }
    if (out == kNone) throw Error("reeb", "internal error: a contour walk lost its way");
    const i32 nxt = topo_.twin[z(out)];
    if (nxt == kNone) return 2;
    if (in_event(nxt / 3, e)) {
        en.partner = end_at(nxt);
        if (en.partner == kNone) throw Error("reeb", "internal error: a contour walk met no end");
        return 1;
    }
    en.cur = nxt;
    return 0;
}

// Ends of one old contour that are still open are settled by counting when possible: as many
// as the boundary ends still to be met all go to the boundary; two with none to meet pair up.
void Sweep::deduce(i32 label) {
    for (auto& lc : label_counts_) {
        if (lc.label != label) continue;
        if (lc.unresolved == 0) return;
        if (lc.unresolved == lc.need_boundary) {
            for (auto& en : ends_)
                if (en.label == label && en.state == 0) en.state = 2;
            lc.need_boundary = lc.unresolved = 0;
        } else if (lc.need_boundary == 0 && lc.unresolved == 2) {
            i32 a = kNone;
            for (std::size_t i = 0; i < ends_.size(); ++i) {
                auto& en = ends_[i];
                if (en.label != label || en.state != 0) continue;
                if (a == kNone) {
                    a = static_cast<i32>(i);
                } else {
                    en.state = ends_[z(a)].state = 1;
                    en.partner = a;
                    ends_[z(a)].partner = static_cast<i32>(i);
                }
            }
            lc.unresolved = 0;
        }
        return;
    }
}

void Sweep::general_event(i32 e, i32 begin, i32 end) {
    // 1. The star of the event: every triangle with a corner in it, once.
    star_.clear();
    for (i32 i = begin; i < end; ++i) {
        const i32 v = g_.node_vertices[z(i)];
        const i32 h0 = topo_.vertex_out[z(v)];
        if (h0 == kNone) continue;
        i32 h = h0;
        for (;;) {
            const i32 t = h / 3;
            // Keep the triangle only from its lowest-numbered corner in the event.
            i32 owner = v;
            for (const i32 c : mesh_.triangles[z(t)])
                if (g_.vertex_nodes[z(c)] == e) owner = std::min(owner, c);
            if (owner == v) star_.push_back(t);
            const i32 tw = topo_.twin[z(prev_he(h))];
            if (tw == kNone || tw == h0) break;
            h = tw;
        }
    }
    std::sort(star_.begin(), star_.end());
    auto star_index = [&](i32 t) {
        return static_cast<i32>(std::lower_bound(star_.begin(), star_.end(), t) - star_.begin());
    };

    // 2. Contours entering the event (before it is processed) and their boundary ends inside
    //    the star; the link components for the node's classification.
    d_in_.clear();
    label_counts_.clear();
    for (const i32 t : star_) {
        const auto& tri = mesh_.triangles[z(t)];
        bool has_lower = false;
        for (const i32 c : tri) has_lower |= g_.vertex_nodes[z(c)] < e;
        if (!has_lower) continue;
        const i32 c = find(tri_label_[z(t)]);
        tri_label_[z(t)] = c;
        if (std::find(d_in_.begin(), d_in_.end(), c) == d_in_.end()) {
            d_in_.push_back(c);
            label_counts_.push_back({c, 0, contours_[z(c)].open});
        }
        for (i32 j = 0; j < 3; ++j) {
            if (topo_.twin[z(3 * t + j)] != kNone) continue;
            const bool pa = g_.vertex_nodes[z(tri[z(j)])] < e;
            const bool pb = g_.vertex_nodes[z(tri[z((j + 1) % 3)])] < e;
            if (pa != pb)
                for (auto& lc : label_counts_)
                    if (lc.label == c) --lc.need_boundary;
        }
    }
    set_links(g_, e, links_.count(mesh_, g_, e, star_));

    // 3. The event is processed from here on. Segments: new mixed triangles of the star joined
    //    across active edges; their exits into the old contours are the ends.
    const std::size_t ns = star_.size();
    seg_parent_.assign(ns, kNone);
    seg_bnd_.assign(ns, 0);
    auto seg_root = [&](i32 x) {
        while (seg_parent_[z(x)] != x) x = seg_parent_[z(x)] = seg_parent_[z(seg_parent_[z(x)])];
        return x;
    };
    for (std::size_t i = 0; i < ns; ++i) {
        const auto& tri = mesh_.triangles[z(star_[i])];
        if (g_.vertex_nodes[z(tri[0])] > e || g_.vertex_nodes[z(tri[1])] > e ||
            g_.vertex_nodes[z(tri[2])] > e)
            seg_parent_[i] = static_cast<i32>(i);
    }
    ends_.clear();
    end_index_.clear();
    std::size_t n_walks = 0;
    for (std::size_t i = 0; i < ns; ++i) {
        if (seg_parent_[i] == kNone) continue;
        const i32 t = star_[i];
        const auto& tri = mesh_.triangles[z(t)];
        for (i32 j = 0; j < 3; ++j) {
            if (processed(tri[z(j)], e) == processed(tri[z((j + 1) % 3)], e)) continue;
            const i32 h = 3 * t + j;
            const i32 tw = topo_.twin[z(h)];
            if (tw == kNone) {
                ++seg_bnd_[i];
            } else if (in_event(tw / 3, e)) {
                const i32 a = seg_root(static_cast<i32>(i)), b = seg_root(star_index(tw / 3));
                if (a != b) seg_parent_[z(std::max(a, b))] = std::min(a, b);
            } else {
                const i32 label = find(tri_label_[z(tw / 3)]);
                if (n_walks == walks_.size()) walks_.emplace_back();
                walks_[n_walks].clear();
                ends_.push_back({static_cast<i32>(i), h, label, tw, kNone,
                                 static_cast<i32>(n_walks++), 0, false});
                end_index_.emplace_back(h, static_cast<i32>(ends_.size() - 1));
                for (auto& lc : label_counts_)
                    if (lc.label == label) ++lc.unresolved;
            }
        }
    }
    std::sort(end_index_.begin(), end_index_.end());

    // 4. Settle every end: walk all open ones in lockstep, deducing what counting allows.
    for (const auto& lc : label_counts_) deduce(lc.label);
    for (bool open = true; open;) {
        open = false;
        for (std::size_t i = 0; i < ends_.size(); ++i) {
            if (ends_[i].state != 0) continue;
            const int r = step(static_cast<i32>(i), e);
            if (r == 0) {
                open = true;
                continue;
            }
            End& en = ends_[i];
            en.complete = true;
            for (auto& lc : label_counts_) {
                if (lc.label != en.label) continue;
                if (r == 1) {
                    End& other = ends_[z(en.partner)];
                    if (other.state != 0) throw Error("reeb", "internal error: end met twice");
                    en.state = other.state = 1;
                    other.partner = static_cast<i32>(i);
                    lc.unresolved -= 2;
                } else {
                    en.state = 2;
                    --lc.unresolved;
                    --lc.need_boundary;
                }
            }
            deduce(en.label);
            open = true;
        }
    }

    // 5. Groups: segments joined through paired ends. Each group is one new contour.
    for (const auto& en : ends_) {
        if (en.state != 1) continue;
        const i32 a = seg_root(en.segment), b = seg_root(ends_[z(en.partner)].segment);
        if (a != b) seg_parent_[z(std::max(a, b))] = std::min(a, b);
    }
    // A piece is walked when one of its ends completed it; a label whose unwalked pieces lie in
    // several groups has all but one group's pieces walked to the end (lockstep again).
    auto piece_done = [&](const End& en) {
        return en.complete || (en.state == 1 && ends_[z(en.partner)].complete);
    };
    for (const i32 label : d_in_) {
        for (;;) {
            i32 group = kNone;
            bool several = false;
            for (const auto& en : ends_)
                if (en.label == label && !piece_done(en)) {
                    const i32 gr = seg_root(en.segment);
                    if (group != kNone && gr != group) several = true;
                    group = gr;
                }
            if (!several) break;
            for (std::size_t i = 0; i < ends_.size(); ++i) {
                End& en = ends_[i];
                if (en.label != label || piece_done(en)) continue;
                if (en.state == 1 && en.partner < static_cast<i32>(i)) continue;  // once per piece
                const i32 expect = en.partner;
                const int r = step(static_cast<i32>(i), e);
                if (r != 0) {
                    if ((r == 1) != (en.state == 1) || (r == 1 && en.partner != expect))
                        throw Error("reeb", "internal error: contour pieces disagree");
                    en.complete = true;
                }
            }
        }
    }

    // 6. New contours: a group keeps the ids of the old contours whose unwalked pieces it holds
    //    (merged by union), or gets a new id; walked pieces and new triangles are relabelled.
    const bool regular = d_in_.size() == 1 && [&] {
        i32 only = kNone;
        for (std::size_t i = 0; i < ns; ++i)
            if (seg_parent_[i] != kNone) {
                if (only != kNone && seg_root(static_cast<i32>(i)) != only) return false;
                only = seg_root(static_cast<i32>(i));
            }
        return only != kNone;
    }();
    const i32 continuing_arc = regular ? contours_[z(d_in_[0])].arc : kNone;
    if (!regular)
        for (const i32 c : d_in_) arcs_[z(contours_[z(c)].arc)].upper = e;
    int groups = 0;
    for (std::size_t i = 0; i < ns; ++i) {
        if (seg_parent_[i] == kNone || seg_root(static_cast<i32>(i)) != static_cast<i32>(i))
            continue;
        ++groups;
        const i32 gr = static_cast<i32>(i);
        i32 id = kNone;
        i32 open = 0;
        for (const auto& en : ends_) {
            if (seg_root(en.segment) != gr) continue;
            if (en.state == 2) ++open;
            if (piece_done(en)) continue;
            const i32 c = find(en.label);
            if (id == kNone)
                id = c;
            else if (c != id)
                contours_[z(c)].parent = id;
        }
        for (std::size_t k = 0; k < ns; ++k)
            if (seg_parent_[k] != kNone && seg_root(static_cast<i32>(k)) == gr) open += seg_bnd_[k];
        const i32 arc = regular ? continuing_arc : new_arc(e);
        if (id == kNone)
            id = new_contour(arc, open);
        else
            contours_[z(id)].arc = arc, contours_[z(id)].open = open;
        for (const auto& en : ends_)
            if (seg_root(en.segment) == gr && en.complete)
                for (const i32 t : walks_[z(en.walk)]) tri_label_[z(t)] = id;
        for (std::size_t k = 0; k < ns; ++k)
            if (seg_parent_[k] != kNone && seg_root(static_cast<i32>(k)) == gr)
                tri_label_[z(star_[k])] = id;
    }
    if (regular) {  // Reeb-regular (a boundary vertex may still have a split link)
        g_.node_lower_links[z(e)] = g_.node_upper_links[z(e)] = 1;
        append_regular(continuing_arc, e);
        return;
    }
    const auto d_down = d_in_.size();
    g_.node_kinds[z(e)] = d_down == 0   ? NodeKind::minimum
                          : groups == 0 ? NodeKind::maximum
                                        : NodeKind::saddle;
}

void Sweep::finish_graph() {
    const std::size_t na = arcs_.size();
    g_.arcs.resize(na);
    g_.arc_offsets.assign(na + 1, 0);
    for (std::size_t a = 0; a < na; ++a) {
        if (arcs_[a].upper == kNone) throw Error("reeb", "internal error: an arc was left open");
        g_.arcs[a] = {arcs_[a].lower, arcs_[a].upper};
        g_.arc_offsets[a + 1] = g_.arc_offsets[a] + arcs_[a].count;
    }
    g_.arc_nodes.resize(static_cast<std::size_t>(g_.arc_offsets[na]));
    for (std::size_t a = 0; a < na; ++a) {
        i32 pos = g_.arc_offsets[a];
        for (i32 n = arcs_[a].head; n != kNone; n = node_next_[z(n)]) g_.arc_nodes[z(pos++)] = n;
    }
}

}  // namespace

bool reeb_is_tree(const TriangleMesh& mesh) {
    return loop_free(mesh);
}

ReebGraph build_reeb_graph(const TriangleMesh& mesh, const std::vector<float>& field,
                           const ReebOptions& options, const ProgressFn& progress) {
    if (field.size() != mesh.vertex_count())
        throw Error("reeb", "the field has " + std::to_string(field.size()) +
                                " values for a mesh of " + std::to_string(mesh.vertex_count()) +
                                " vertices");
    for (std::size_t v = 0; v < field.size(); ++v)
        if (std::isnan(field[v]))
            throw Error("reeb", "the field is NaN at vertex " + std::to_string(v));
    if (mesh.vertex_count() >= static_cast<std::size_t>(INT32_MAX / 4))
        throw Error("reeb", "the mesh is too large (more than 500 million vertices)");
    ReebGraph g;
    if (options.algorithm == ReebAlgorithm::sweep) {
        Sweep(mesh, field, g).run(progress, false);
        return g;
    }
    order_events(mesh, field, g);
    report_progress(progress, 0.2, "reeb: order");
    if (contour_tree(mesh, g, progress)) {
        report_progress(progress, 1.0, "reeb");
        return g;
    }
    if (options.algorithm == ReebAlgorithm::contour_tree)
        throw Error("reeb",
                    "the contour-tree algorithm needs a mesh whose components are disks "
                    "or spheres; this one has handles or holes");
    // Handles or holes: the sweep, on the same events.
    const ProgressFn rest = [&](double f, std::string_view message) {
        return progress ? progress(0.3 + 0.7 * f, message) : true;
    };
    Sweep(mesh, field, g).run(rest, true);
    return g;
}

}  // namespace terrain::reeb
