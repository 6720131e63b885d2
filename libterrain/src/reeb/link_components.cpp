// Link components (paper s.2.1): a node's lower (upper) link is the part of the ring of
// vertices around it that lies below (above) it, with the star's edges between them; the
// numbers of components of the two classify the node (regular 1/1, Morse saddle 2/2, ...) and
// name the components that the contour tree's join and split sweeps unite (one union-find
// step per component instead of one per neighbour). Two ways to count: in bulk for
// single-vertex nodes from local counts (link_components), and by union-find over the star
// for plateaus and very high degrees (LinkCounter, also used by the contour-tracking sweep).

#include "link_components.hpp"

#include <tbb/blocked_range.h>

#include <algorithm>

#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/mesh/grid_triangles.hpp"

namespace terrain::reeb::internal {

using detail::idx;
using detail::kNone;

std::pair<int, int> LinkCounter::count(const TriangleMesh& mesh, const ReebGraph& g, i32 e,
                                       const std::vector<i32>& star) {
    return count_star(
        g, e,
        star.size(), [&](std::size_t i) -> const auto& { return mesh.triangles()[idx(star[i])]; });
}

std::pair<int, int> LinkCounter::count(const ReebGraph& g, i32 e,
                                       const std::vector<std::array<i32, 3>>& star) {
    return count_star(
        g, e, star.size(), [&](std::size_t i) -> const auto& { return star[i]; });
}

template <class Corners>
std::pair<int, int> LinkCounter::count_star(const ReebGraph& g, i32 e, std::size_t size,
                                            const Corners& corners) {
    verts_.clear();
    for (std::size_t i = 0; i < size; ++i)
        for (const i32 c : corners(i))
            if (g.vertex_nodes[idx(c)] != e) verts_.push_back(c);
    std::sort(verts_.begin(), verts_.end());
    verts_.erase(std::unique(verts_.begin(), verts_.end()), verts_.end());
    components_.reset(verts_.size());
    auto index = [&](i32 v) {
        return static_cast<i32>(std::lower_bound(verts_.begin(), verts_.end(), v) - verts_.begin());
    };
    for (std::size_t i = 0; i < size; ++i) {
        const auto& tri = corners(i);
        for (int j = 0; j < 3; ++j) {
            const i32 a = tri[idx(j)], b = tri[idx((j + 1) % 3)];
            const i32 na = g.vertex_nodes[idx(a)], nb = g.vertex_nodes[idx(b)];
            if (na == e || nb == e || (na < e) != (nb < e)) continue;
            components_.unite(index(b), index(a));
        }
    }
    int lower = 0, upper = 0;
    for (std::size_t i = 0; i < verts_.size(); ++i)
        if (components_.is_root(static_cast<i32>(i)))
            ++(g.vertex_nodes[idx(verts_[i])] < e ? lower : upper);
    return {lower, upper};
}

namespace {

// starts[0..1]: lower runs' first vertices, starts[2..3]: upper runs'; runs[0], runs[1]:
// how many lower and upper runs were seen.
struct Star {
    std::array<i32, 4> starts;
    std::uint8_t triangles, lower_edges, upper_edges;
    std::array<std::uint8_t, 2> runs;
};

// The stars of a part [lo, hi) of the vertices, gathered from every triangle (add), and each
// of the part's vertices' node's link counts and representatives read from them (vertex).
// The vertices in parallel: each writes its own entries and its node's, and a node of
// several vertices (a plateau) is written from its first vertex only.
struct PartStars {
    const TriangleMesh& mesh;
    const ReebGraph& g;
    std::vector<std::uint8_t>& lower_links;
    std::vector<std::uint8_t>& upper_links;
    std::vector<char>& general;
    std::vector<LinkReps>& reps;
    const std::vector<i32>& node;  // g.vertex_nodes
    std::vector<Star> stars;
    std::size_t lo = 0, hi = 0;  // the part's vertices

    Star* star(i32 c) {
        const std::size_t v = idx(c);
        return v >= lo && v < hi ? &stars[v - lo] : nullptr;
    }

    void add(const std::array<i32, 3>& t) {
        const std::array<i32, 3> n{node[idx(t[0])], node[idx(t[1])], node[idx(t[2])]};
        for (const i32 c : t)
            if (Star* s = star(c)) ++s->triangles;
        if (n[0] != n[1] && n[1] != n[2] && n[0] != n[2]) {
            // The highest corner sees a lower link edge, the lowest an upper one; going round
            // the middle corner counter-clockwise, the step a -> b crosses its value: b starts
            // a lower run when a is above, an upper run when a is below. No branches: the
            // orders are unpredictable.
            const int top = n[0] > n[1] ? (n[0] > n[2] ? 0 : 2) : (n[1] > n[2] ? 1 : 2);
            const int bottom = n[0] < n[1] ? (n[0] < n[2] ? 0 : 2) : (n[1] < n[2] ? 1 : 2);
            const int mid = 3 - top - bottom, a = mid == 2 ? 0 : mid + 1, b = 3 - mid - a;
            if (Star* s = star(t[idx(top)])) ++s->lower_edges;
            if (Star* s = star(t[idx(bottom)])) ++s->upper_edges;
            if (Star* s = star(t[idx(mid)])) {
                const int side = n[idx(a)] > n[idx(mid)] ? 0 : 1;
                s->starts[idx(2 * side + (s->runs[idx(side)] & 1))] = n[idx(b)];
                ++s->runs[idx(side)];
            }
            return;
        }
        // Two corners in one node (a plateau): the third sees an edge of its lower or upper
        // link; the plateau's corners see an edge touching their node, which does not count.
        for (int k = 0; k < 3; ++k) {
            Star* s = star(t[idx(k)]);
            if (!s) continue;
            const i32 m = n[idx(k)], p = n[idx((k + 1) % 3)], q = n[idx((k + 2) % 3)];
            s->lower_edges += (m > p) & (m > q);
            s->upper_edges += (m < p) & (m < q);
        }
    }

    void vertex(std::size_t v, std::size_t end) {
        constexpr std::size_t kAhead = 16;  // the nodes' entries are written in random order
        if (v + kAhead < end) {
            const std::size_t ahead = idx(node[v + kAhead]);
            __builtin_prefetch(&reps[ahead], 1);
            __builtin_prefetch(&lower_links[ahead], 1);
            __builtin_prefetch(&upper_links[ahead], 1);
        }
        const i32 n = node[v];
        const auto neighbours = mesh.neighbors_of(v);
        const auto degree = static_cast<i32>(neighbours.size());
        int below = 0, same = 0;
        i32 some_below = kNone, some_above = kNone;
        for (const i32 w : neighbours) {
            const i32 m = node[idx(w)];
            below += m < n;
            same += m == n;  // a plateau
            some_below = m < n ? m : some_below;
            some_above = m < n ? some_above : m;
        }
        if (degree > 250 || same > 0) {
            if (same > 0 && g.node_vertices[idx(g.node_vertex_offsets[idx(n)])] != i32(v)) return;
            general[idx(n)] = 1;
            reps[idx(n)] = {{kSeveral, kNone}, {kSeveral, kNone}};
            return;
        }
        const int above = degree - below;
        const Star& s = stars[v - lo];
        const bool interior = s.triangles == degree;
        const int lower = (above == 0 && interior && below > 0) ? 1 : below - s.lower_edges;
        const int upper = (below == 0 && interior && above > 0) ? 1 : above - s.upper_edges;
        // (A single-vertex node: its bytes are written from this vertex only.)
        lower_links[idx(n)] = static_cast<std::uint8_t>(lower);
        upper_links[idx(n)] = static_cast<std::uint8_t>(upper);
        auto side = [&](int count, i32 some, int runs, i32 first, i32 second) {
            if (count <= 1) return std::array<i32, 2>{count == 0 ? kNone : some, kNone};
            if (count == 2 && runs == 2)
                return std::array<i32, 2>{std::min(first, second), std::max(first, second)};
            return std::array<i32, 2>{kSeveral, kNone};
        };
        reps[idx(n)] = {side(lower, some_below, s.runs[0], s.starts[0], s.starts[1]),
                        side(upper, some_above, s.runs[1], s.starts[2], s.starts[3])};
    }
};

}  // namespace

std::vector<LinkReps> link_components(const TriangleMesh& mesh, const ReebGraph& g,
                                      std::vector<std::uint8_t>& lower_links,
                                      std::vector<std::uint8_t>& upper_links,
                                      std::vector<char>& general, const ProgressFn& progress,
                                      std::size_t parts) {
    const std::size_t nv = mesh.vertex_count(), nn = g.node_count();
    // Its passes, for each part of the vertices (below): the triangles, then the vertices.
    // The stars are gathered for a part of the vertices at a time, each part in a pass over
    // every triangle, and read for those vertices: their records (24 bytes a vertex) are then
    // not whole beside the nodes' representatives (16 bytes a node), which set the Reeb graph's
    // peak of memory. Three parts on large meshes: two more passes over the triangles, 16
    // bytes a vertex less. (What a star gathers is the same in any part: its own triangles.)
    // An empty mesh: one part of nothing.
    if (parts == 0) parts = nv >= kPartedStars ? 3 : 1;
    parts = std::max<std::size_t>(1, std::min(parts, nv));
    std::vector<LinkReps> reps;
    PartStars part_stars{mesh, g, lower_links, upper_links, general, reps, g.vertex_nodes, {},
                         0,    0};
    std::vector<Star>& stars = part_stars.stars;
    std::size_t& lo = part_stars.lo;
    std::size_t& hi = part_stars.hi;
    const auto add = [&](const std::array<i32, 3>& t) { part_stars.add(t); };
    const auto vertex = [&](std::size_t v, std::size_t end) { part_stars.vertex(v, end); };
    // Each part's share of the progress: its stars made (a fifth), its triangles (three
    // fifths), its vertices (the rest); the representatives made before the first vertices.
    for (std::size_t part = 0; part < parts; ++part) {
        const double from = double(part) / double(parts), share = 1.0 / double(parts);
        const auto at = [&](double f) { return from + share * f; };
        lo = nv * part / parts;
        hi = nv * (part + 1) / parts;
        // (Made a slice at a time: the first touch of a large block is slow,
        // docs/performance.md.)
        detail::assign_in_slices(stars, hi - lo,
                                 Star{{kNone, kNone, kNone, kNone}, 0, 0, 0, {0, 0}},
                                 detail::PassProgress(progress, at(0), at(0.2), "reeb: links"));
        // (Through grid_triangles.hpp: a DEM mesh may have released its triangles; a released
        // grid goes in bands of rows in parallel.)
        detail::for_each_triangle_by_bands(mesh, progress, at(0.2), at(0.6), "reeb: links", add);
        if (part == 0) {
            detail::assign_in_slices(
                reps, nn, LinkReps{},
                detail::PassProgress(progress, at(0.6), at(0.65), "reeb: links"));
            general.assign(nn, 0);
        }
        detail::parallel_slices(hi - lo, std::size_t{1} << 14, progress, at(0.65), at(1.0),
                                "reeb: links", [&](const tbb::blocked_range<std::size_t>& r) {
                                    for (std::size_t v = lo + r.begin(); v < lo + r.end(); ++v)
                                        vertex(v, lo + r.end());
                                });
    }
    return reps;
}

// The link counts of the critical nodes that link_components left (plateaus, vertices of very
// high degree), from their stars' triangles.
void count_general_links(const TriangleMesh& mesh, ReebGraph& g, const std::vector<char>& general,
                         const ProgressFn& progress) {
    std::vector<char> wanted;  // per vertex
    for (std::size_t n = 0; n < g.node_count(); ++n) {
        if (!general[n] || g.node_kinds[n] == NodeKind::regular) continue;
        if (wanted.empty()) wanted.assign(mesh.vertex_count(), 0);
        for (i32 i = g.node_vertex_offsets[n]; i < g.node_vertex_offsets[n + 1]; ++i)
            wanted[idx(g.node_vertices[idx(i)])] = 1;
    }
    if (wanted.empty()) return;
    // (node, triangle's index, its corners), through for_each_triangle: a DEM mesh may have
    // released its triangles.
    struct Entry {
        i32 node, triangle;
        std::array<i32, 3> corners;
    };
    std::vector<Entry> star;
    const detail::PassProgress heartbeat(progress, 0, 0, "reeb: links");
    const std::size_t nt = mesh.triangle_count();
    detail::for_each_triangle(mesh, [&](std::size_t t, const std::array<i32, 3>& corners) {
        heartbeat.at(t, nt);
        for (const i32 c : corners)
            if (wanted[idx(c)])
                star.push_back({g.vertex_nodes[idx(c)], static_cast<i32>(t), corners});
    });
    std::sort(star.begin(), star.end(), [](const Entry& a, const Entry& b) {
        return a.node != b.node ? a.node < b.node : a.triangle < b.triangle;
    });
    LinkCounter counter;
    std::vector<std::array<i32, 3>> tris;
    for (std::size_t i = 0; i < star.size();) {
        const i32 n = star[i].node;
        tris.clear();
        for (; i < star.size() && star[i].node == n; ++i) tris.push_back(star[i].corners);
        set_links(g, n, counter.count(g, n, tris));
    }
}

}  // namespace terrain::reeb::internal
