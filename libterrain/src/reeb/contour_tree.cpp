// The contour tree of a field on a mesh without loops (paper s.3.1 on disks and spheres; Carr,
// Snoeyink & Axen 2003, "Computing contour trees in all dimensions"). The join tree and the
// split tree come from two union-find sweeps over the events, upwards then downwards; they
// are merged leaf by leaf into the augmented contour tree (each removed leaf is
// one edge), whose chains of regular nodes become the arcs. The sweeps unite link components
// (link_components.cpp), not neighbours. The join tree also tells whether the mesh has loops
// (its roots are the components; a single component is a disk or a sphere exactly when
// V - E + F is 1 or 2): then the caller falls back to the contour-tracking sweep.

#include "contour_tree.hpp"

#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <numeric>
#include <thread>
#include <utility>
#include <vector>

#include "link_components.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/disjoint_sets.hpp"
#include "terrain/internal/core/indices.hpp"
#include "terrain/internal/core/key_parts.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/release.hpp"
#include "terrain/internal/mesh/grid_triangles.hpp"

namespace terrain::reeb::internal {

using detail::i32;
using detail::idx;
using detail::kNone;

namespace {

// Whether a DEM mesh is one connected piece by its grid alone: every pixel has its vertex
// (none missing, none split at a pinch, none left out), so that every pixel is a corner of
// the triangles of the blocks around it and neighbouring blocks share corners.
bool whole_grid(const TriangleMesh& mesh) {
    if (!mesh.grid_adjacency() || mesh.pinched_vertices != 0 || mesh.isolated_vertices != 0 ||
        mesh.grid_width < 2 || mesh.grid_height < 2 ||
        mesh.pixel_vertex.size() != std::size_t(mesh.grid_width) * std::size_t(mesh.grid_height))
        return false;
    return std::all_of(mesh.pixel_vertex.begin(), mesh.pixel_vertex.end(),
                       [](std::int32_t v) { return v >= 0; });
}

// A mesh known to be one component is a disk or a sphere exactly when its Euler
// characteristic, V - E + F from its counts, is 1 or 2.
bool one_component_loop_free(const TriangleMesh& mesh) {
    const auto chi = static_cast<std::int64_t>(mesh.vertex_count()) -
                     static_cast<std::int64_t>(mesh.edge_count()) +
                     static_cast<std::int64_t>(mesh.triangle_count());
    return chi == 1 || chi == 2;
}

}  // namespace

bool loop_free(const TriangleMesh& mesh, const ProgressFn& progress) {
    // One component: no pass over the triangles is needed (a whole grid is one).
    if (whole_grid(mesh)) {
        report_progress(progress, 1.0, "reeb: loops");
        return one_component_loop_free(mesh);
    }
    return loop_free_by_components(mesh, progress);
}

bool loop_free_by_components(const TriangleMesh& mesh, const ProgressFn& progress) {
    // A component's Euler characteristic is 2 - 2g - b: it is 1 or 2 exactly when the
    // component is a disk (g = 0, b = 1) or a sphere (g = 0, b = 0).
    const std::size_t nv = mesh.vertex_count(), nt = mesh.triangle_count();
    // Its passes: the triangles (0 to 0.4), the vertices (to 0.7), the triangles (to 1).
    const detail::PassProgress joined(progress, 0, 0.4, "reeb: loops"),
        counted(progress, 0.4, 0.7, "reeb: loops"), closed(progress, 0.7, 1, "reeb: loops");
    // (Triangles through for_each_triangle: a DEM mesh may have released them.)
    using Corners = std::array<i32, 3>;
    detail::DisjointSets<i32> components(nv);  // each rooted at its lowest vertex
    detail::for_each_triangle(mesh, [&](std::size_t i, const Corners& t) {
        joined.at(i, nt);
        for (int k = 0; k < 2; ++k) components.unite_to_smaller(t[idx(k)], t[idx(k + 1)]);
    });
    std::vector<std::int64_t> chi(nv, 0);
    for (std::size_t v = 0; v < nv; ++v) {
        counted.at(v, nv);
        std::int64_t upper_neighbours = 0;
        for (const i32 w : mesh.neighbors_of(v)) upper_neighbours += idx(w) > v;
        chi[idx(components.find(static_cast<i32>(v)))] += 1 - upper_neighbours;
    }
    detail::for_each_triangle(mesh, [&](std::size_t i, const Corners& t) {
        closed.at(i, nt);
        chi[idx(components.find(t[0]))] += 1;
    });
    report_progress(progress, 1.0, "reeb: loops");
    for (std::size_t v = 0; v < nv; ++v)
        if (components.is_root(static_cast<i32>(v)) && chi[v] != 1 && chi[v] != 2) return false;
    return true;
}

namespace {

// The nodes around each node whose link a sweep reads vertex by vertex (kSeveral on a side:
// a plateau, more than two link components, a vertex of very high degree; few on a
// terrain), in the order the sweep reads them (its vertices', each one's neighbours' in
// order); list l is nodes[offsets[l] .. offsets[l + 1]), and its number is in the second
// representative of such a side. The sweeps then read neither the graph's vertex lists, its
// vertices' nodes nor the mesh, and the caller may park the first two through them.
struct NodesAround {
    std::vector<std::size_t> offsets{0};
    std::vector<i32> nodes;
};

NodesAround nodes_around(const TriangleMesh& mesh, const ReebGraph& g,
                         std::vector<LinkReps>& reps) {
    NodesAround out;
    for (std::size_t e = 0; e < g.node_count(); ++e) {
        LinkReps& r = reps[e];
        if (r.lower[0] != kSeveral && r.upper[0] != kSeveral) continue;
        const auto list = static_cast<i32>(out.offsets.size() - 1);
        if (r.lower[0] == kSeveral) r.lower[1] = list;
        if (r.upper[0] == kSeveral) r.upper[1] = list;
        for (i32 i = g.node_vertex_offsets[e]; i < g.node_vertex_offsets[e + 1]; ++i)
            for (const i32 w : mesh.neighbors_of(idx(g.node_vertices[idx(i)])))
                out.nodes.push_back(g.vertex_nodes[idx(w)]);
        out.offsets.push_back(out.nodes.size());
    }
    return out;
}

// The join tree and the split tree: each event's parent in the join tree (below it) and in
// the split tree (above it), and its children in each.
struct JoinSplitTrees {
    std::vector<i32> join_parent, split_parent;
    std::vector<std::array<i32, 2>> children;  // (join, split)
};

// One union-find sweep over the components of the part swept so far (the sublevel set for
// the join tree, the superlevel set for the split tree). A node's entry holds its parent,
// or (at a root) minus one minus its rank, and the last event added to its component (the
// component's head, where the next event joining it hangs in the tree). Union by rank with
// the head beside the link, in one record: not detail::DisjointSets, on the hottest path.
// Most events have one link component below (above): one find, and the event hangs under
// the root. The join (ascending) and split (descending) sweeps are independent: they run
// side by side, each with its own records (8 bytes a node) and its own side of `children`
// (side by side they take about the time of one). The 12 bytes a node this holds more
// than one sweep at a time are the arrays parked through them (contour_tree).
struct Entry {
    i32 up, head;
};

// Progress: the events both sweeps have passed, counted together, reported (0.3 to 0.6)
// only from the caller's thread (the callback may not be called from another). Either
// sweep may run there, or both one after the other in either order: the count is what
// keeps the fraction from going back.
struct SweepProgress {
    const ProgressFn& progress;
    std::thread::id caller = std::this_thread::get_id();
    std::atomic<std::size_t> swept_events{0};
    std::size_t nn = 0;
    double fraction(std::size_t events) const {
        return 0.3 + 0.3 * double(events) / double(std::max<std::size_t>(1, 2 * nn));
    }
};

void sweep(bool ascending, const std::vector<LinkReps>& reps, const NodesAround& around_lists,
           SweepProgress& swept_progress, std::vector<i32>& tree_parent,
           std::vector<std::array<i32, 2>>& children, std::vector<Entry>& swept) {
    const std::size_t nn = reps.size();
    const std::vector<std::size_t>& around_offsets = around_lists.offsets;
    const std::vector<i32>& around = around_lists.nodes;
    const ProgressFn& progress = swept_progress.progress;
    const std::size_t side = ascending ? 0 : 1;
    const bool reports = progress && std::this_thread::get_id() == swept_progress.caller;
    const auto passed = [&](std::size_t k) {
        constexpr std::size_t kStep = std::size_t{1} << 18;
        if ((k & (kStep - 1)) != kStep - 1) return;
        const std::size_t all = swept_progress.swept_events.fetch_add(kStep) + kStep;
        if (reports)
            report_progress(progress, swept_progress.fraction(all), "reeb: join and split trees");
    };
    auto find = [&](i32 x) {
        i32 r = x;
        while (swept[idx(r)].up >= 0) r = swept[idx(r)].up;
        while (x != r) {
            const i32 nx = swept[idx(x)].up;
            swept[idx(x)].up = r;
            x = nx;
        }
        return r;
    };
    auto reps_at = [&](std::size_t k) -> const std::array<i32, 2>& {
        return ascending ? reps[k].lower : reps[nn - 1 - k].upper;
    };
    // Paths are short: two steps up without branching, then the rare longer path.
    auto find_short = [&](i32 x) {
        const i32 ux = swept[idx(x)].up;
        const i32 b = ux >= 0 ? ux : x;
        const i32 ub = swept[idx(b)].up;
        i32 c = ub >= 0 ? ub : b;
        if (swept[idx(c)].up >= 0) [[unlikely]]
            c = find(c);
        swept[idx(x)].up = ux >= 0 ? c : ux;
        return c;
    };
    // The sweep waits on memory: the entries of the representatives a few events ahead
    // are fetched early (and, from those, their parents').
    constexpr std::size_t kAhead = 16;
    auto prefetch = [&](i32 x) { __builtin_prefetch(&swept[idx(x >= 0 && idx(x) < nn ? x : 0)]); };
    // Component c (a root) joins the component of event e whose root is cur, by rank (the
    // higher rank has the lower `up`); returns the new root.
    auto join = [&](i32 cur, i32 c, i32 e) {
        tree_parent[idx(swept[idx(c)].head)] = e;
        ++children[idx(e)][side];
        const bool cur_higher = swept[idx(cur)].up <= swept[idx(c)].up;
        const i32 hi = cur_higher ? cur : c, lo = cur_higher ? c : cur;
        if (swept[idx(hi)].up == swept[idx(lo)].up) --swept[idx(hi)].up;
        swept[idx(lo)].up = hi;
        swept[idx(hi)].head = e;
        return hi;
    };
    std::vector<i32> roots;
    for (std::size_t k = 0; k < nn; ++k) {
        passed(k);
        if (k + kAhead < nn) {
            const auto& r = reps_at(k + kAhead);
            prefetch(r[0]);
            prefetch(r[1]);
        }
        if (k + kAhead / 2 < nn) {
            const auto& r = reps_at(k + kAhead / 2);
            if (r[0] >= 0) prefetch(swept[idx(r[0])].up);
            if (r[1] >= 0) prefetch(swept[idx(r[1])].up);
        }
        const i32 e = static_cast<i32>(ascending ? k : nn - 1 - k);
        const auto& rep = reps_at(k);
        if (rep[0] >= 0) {
            // The event hangs under the component of its first link component.
            const i32 c = find_short(rep[0]);
            Entry& root = swept[idx(c)];
            tree_parent[idx(root.head)] = e;
            children[idx(e)][side] = 1;
            swept[idx(e)].up = c;
            root.head = e;
            root.up -= root.up == -1;  // rank 0 -> 1
            if (rep[1] < 0) continue;
            const i32 o = find_short(rep[1]);
            if (o != c) join(c, o, e);  // a second component joins here
            continue;
        }
        swept[idx(e)] = {-1, e};
        children[idx(e)][side] = 0;
        if (rep[0] == kNone) continue;
        roots.clear();
        const std::size_t list = idx(rep[1]);  // (rep[0] is kSeveral)
        for (std::size_t i = around_offsets[list]; i < around_offsets[list + 1]; ++i) {
            const i32 n = around[i];
            if (ascending ? n >= e : n <= e) continue;
            const i32 c = find(n);
            if (std::find(roots.begin(), roots.end(), c) == roots.end()) roots.push_back(c);
        }
        i32 cur = e;
        for (const i32 c : roots) cur = join(cur, c, e);
    }
}

// The join and split trees of the events in order, the two sweeps side by side; progress
// 0.3 to 0.6.
JoinSplitTrees join_and_split_trees(const std::vector<LinkReps>& reps, const NodesAround& around,
                                    const ProgressFn& progress) {
    const std::size_t nn = reps.size();
    // (Large blocks made a slice at a time, the sweeps' own too: their first touch is slow,
    // docs/performance.md. The sweeps' progress starts at 0.3.)
    const auto made = [&] {
        return detail::PassProgress(progress, 0.3, 0.3, "reeb: join and split trees");
    };
    JoinSplitTrees trees;
    detail::assign_in_slices(trees.join_parent, nn, kNone, made());
    detail::assign_in_slices(trees.split_parent, nn, kNone, made());
    // Children in the join and split trees. The sweeps run in opposite directions, so they
    // share cache lines only where they cross.
    detail::assign_in_slices(trees.children, nn, std::array<i32, 2>{}, made());
    SweepProgress swept{progress};
    swept.nn = nn;
    // (Whichever sweep runs on the caller's thread reports the progress of both.)
    std::vector<Entry> joined, split;
    detail::assign_in_slices(joined, nn, Entry{-1, 0}, made());
    detail::assign_in_slices(split, nn, Entry{-1, 0}, made());
    tbb::task_group both;
    both.run([&] { sweep(false, reps, around, swept, trees.split_parent, trees.children, split); });
    sweep(true, reps, around, swept, trees.join_parent, trees.children, joined);
    both.wait();
    return trees;
}

// Merge: remove leaves one by one; each removal is one edge of the augmented tree. A
// removed node's join-children count is set to -1. Returns attach: attach[x] = 2 * y + (x
// was below y), kNone for the last node; progress 0.6 to 0.75.
std::vector<i32> merge_trees(JoinSplitTrees& trees, const ProgressFn& progress) {
    auto& children = trees.children;
    auto& join_parent = trees.join_parent;
    auto& split_parent = trees.split_parent;
    const std::size_t nn = children.size();
    auto dead = [&](i32 x) { return children[idx(x)][0] < 0; };
    auto next_alive = [&](std::vector<i32>& parent, i32 x) {
        i32 p = parent[idx(x)];
        while (p != kNone && dead(p)) p = parent[idx(p)];
        for (i32 q = parent[idx(x)]; q != p;) {
            const i32 nx = parent[idx(q)];
            parent[idx(q)] = p;
            q = nx;
        }
        parent[idx(x)] = p;
        return p;
    };
    auto is_leaf = [&](i32 x) {
        const auto [j, s] = children[idx(x)];
        return (j == 0 && s == 1) || (s == 0 && j == 1);
    };
    std::vector<i32> queue, attach(nn, kNone);
    queue.reserve(nn);
    const detail::PassProgress leaves(progress, 0.6, 0.65, "reeb: contour tree"),
        merged(progress, 0.65, 0.75, "reeb: contour tree");
    for (std::size_t n = 0; n < nn; ++n) {
        leaves.at(n, nn);
        if (is_leaf(static_cast<i32>(n))) queue.push_back(static_cast<i32>(n));
    }
    constexpr std::size_t kAhead = 16;  // as in the sweeps: fetch the next leaves' entries early
    for (std::size_t qi = 0; qi < queue.size(); ++qi) {
        merged.at(qi, nn);  // about nn leaves in all
        if (qi + kAhead < queue.size()) {
            const i32 x = queue[qi + kAhead];
            __builtin_prefetch(&children[idx(x)]);
            __builtin_prefetch(&join_parent[idx(x)]);
            __builtin_prefetch(&split_parent[idx(x)]);
        }
        if (qi + kAhead / 2 < queue.size()) {
            const i32 x = queue[qi + kAhead / 2];
            const i32 p = (children[idx(x)][0] == 0 ? join_parent : split_parent)[idx(x)];
            __builtin_prefetch(&children[idx(p >= 0 ? p : 0)]);
        }
        const i32 x = queue[qi];
        if (dead(x) || !is_leaf(x)) continue;
        const bool lower = children[idx(x)][0] == 0;
        const i32 y = next_alive(lower ? join_parent : split_parent, x);
        if (y == kNone) throw Error("reeb", "internal error: contour tree leaf without parent");
        children[idx(x)][0] = -1;
        attach[idx(x)] = 2 * y + lower;
        --children[idx(y)][lower ? 0 : 1];
        if (is_leaf(y)) queue.push_back(y);
    }
    detail::release(queue);
    detail::release(children);
    detail::release(join_parent);
    detail::release(split_parent);
    report_progress(progress, 0.75, "reeb: contour tree");
    return attach;
}

// The tree's edges (x, attach[x] >> 1) as up-edges per node (CSR, in the order of the
// removed leaves' indices, up_off and up_to) and the node kinds from the degrees; progress
// 0.75 to 0.825.
void tree_edges(ReebGraph& g, const std::vector<i32>& attach, std::vector<i32>& up_off,
                std::vector<i32>& up_to, const ProgressFn& progress) {
    const std::size_t nn = attach.size();
    std::vector<i32> down_deg;
    const auto arcs_made = [&](double from) {
        return detail::PassProgress(progress, from, from, "reeb: arcs");
    };
    detail::assign_in_slices(up_off, nn + 1, 0, arcs_made(0.75));
    detail::assign_in_slices(up_to, nn, 0, arcs_made(0.75));
    detail::assign_in_slices(down_deg, nn, 0, arcs_made(0.75));
    // Its passes over the nodes: 0.75 to 0.9.
    const auto span = [&](double from, double to) {
        return detail::PassProgress(progress, from, to, "reeb: arcs");
    };
    constexpr std::size_t kGrain = std::size_t{1} << 14;  // the passes in parallel
    auto edge = [&](std::size_t x) {
        const i32 y = attach[x] >> 1, self = static_cast<i32>(x);
        return (attach[x] & 1) ? std::pair{self, y} : std::pair{y, self};
    };
    // The passes that write to random places go by parts of the places (key_parts.hpp): in
    // parallel, each place written in the serial order. Critical nodes are the arcs' ends.
    const auto lower_end = [&](std::size_t x) -> std::int64_t {
        return attach[x] == kNone ? -1 : edge(x).first;
    };
    detail::count_by_key_parts(nn, up_off, span(0.75, 0.76), lower_end);
    detail::scatter_by_key_parts(
        nn, nn, span(0.76, 0.775),
        [&](std::size_t x) -> std::int64_t { return attach[x] == kNone ? -1 : edge(x).second; },
        [&](std::size_t, std::size_t hi) { ++down_deg[hi]; });
    detail::place_by_key_parts(
        nn, up_off, span(0.775, 0.8), lower_end,
        [&](std::size_t x, std::size_t slot) { up_to[slot] = edge(x).second; });
    g.node_kinds.assign(nn, NodeKind::regular);
    // (Each node its own entries: in parallel.)
    detail::parallel_slices(
        nn, kGrain, progress, 0.8, 0.825, "reeb: arcs",
        [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t n = r.begin(); n < r.end(); ++n) {
                const int d = down_deg[n], u = up_off[n + 1] - up_off[n];
                if (d == 1 && u == 1) {  // Reeb-regular, whatever its link: links 1, 1
                    g.node_lower_links[n] = g.node_upper_links[n] = 1;
                    continue;
                }
                g.node_kinds[n] = d == 0   ? NodeKind::minimum
                                  : u == 0 ? NodeKind::maximum
                                           : NodeKind::saddle;
                // (A single-vertex node's links are link_components'; the general nodes' are
                // counted below.)
            }
        });
    detail::release(down_deg);  // (the kinds are known: read no more)
}

// The arcs from the tree's edges: chains of regular nodes between critical nodes, each
// node's arc and each arc's nodes; progress 0.825 to 0.9. `below` is attach, reused.
void arcs_from_edges(ReebGraph& g, std::vector<i32>& below, std::vector<i32>& up_off,
                     std::vector<i32>& up_to, const ProgressFn& progress) {
    const std::size_t nn = below.size();
    const auto arcs_made = [&](double from) {
        return detail::PassProgress(progress, from, from, "reeb: arcs");
    };
    const auto span = [&](double from, double to) {
        return detail::PassProgress(progress, from, to, "reeb: arcs");
    };
    constexpr std::size_t kGrain = std::size_t{1} << 14;  // the passes in parallel
    // Arcs in the order of their lower nodes, then of their up-edges: a critical node's first
    // arc is the number of up-edges of the critical nodes before it (held in node_arcs until
    // the regular nodes take their arcs there). A regular node takes the arc of the edge
    // below it; `below` holds that edge as the regular node under it, or as -2 - arc when the
    // edge leaves a critical node.
    auto critical = [&](i32 n) { return g.node_kinds[idx(n)] != NodeKind::regular; };
    detail::assign_in_slices(g.node_arcs, nn, kNone, arcs_made(0.825));
    std::size_t arc_count = 0;
    const auto counted = span(0.825, 0.835);
    for (std::size_t n = 0; n < nn; ++n) {
        counted.at(n, nn);
        if (!critical(static_cast<i32>(n))) continue;
        g.node_arcs[n] = static_cast<i32>(arc_count);
        arc_count += idx(up_off[n + 1] - up_off[n]);
    }
    if (arc_count > std::size_t{INT32_MAX})
        throw Error("reeb", "the graph has more arcs than 32-bit ids can name");
    detail::assign_in_slices(g.arcs, arc_count, std::array<i32, 2>{kNone, kNone}, arcs_made(0.835));
    // (Each critical node writes its own arcs, each regular node's `below` is written from
    // its one edge below: in parallel.)
    detail::parallel_slices(
        nn, kGrain, progress, 0.835, 0.85, "reeb: arcs",
        [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t lo = r.begin(); lo < r.end(); ++lo) {
                const bool from_critical = critical(static_cast<i32>(lo));
                for (i32 k = up_off[lo]; k < up_off[lo + 1]; ++k) {
                    const i32 hi = up_to[idx(k)];
                    if (from_critical) {
                        const i32 arc = g.node_arcs[lo] + (k - up_off[lo]);
                        g.arcs[idx(arc)] = {static_cast<i32>(lo), critical(hi) ? hi : kNone};
                        if (!critical(hi)) below[idx(hi)] = -2 - arc;
                    } else if (!critical(hi)) {
                        below[idx(hi)] = static_cast<i32>(lo);
                    }
                }
            }
        });
    // A regular node whose edge below leaves a critical node knows its arc (in parallel);
    // the others take their lower neighbour's, which comes first in one pass in increasing
    // order: no chain is followed.
    constexpr i32 kLater = -2;
    detail::parallel_slices(nn, kGrain, progress, 0.85, 0.86, "reeb: arcs",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t n = r.begin(); n < r.end(); ++n) {
                                    if (critical(static_cast<i32>(n))) {
                                        g.node_arcs[n] = kNone;
                                        continue;
                                    }
                                    const i32 b = below[n];
                                    g.node_arcs[n] = b >= 0 ? kLater : -2 - b;
                                }
                            });
    const auto taken = span(0.86, 0.87);
    for (std::size_t n = 0; n < nn; ++n) {
        taken.at(n, nn);
        if (g.node_arcs[n] == kLater) g.node_arcs[n] = g.node_arcs[idx(below[n])];
    }
    // Each arc's upper end, from its highest regular node (one an arc: in parallel).
    detail::parallel_slices(nn, kGrain, progress, 0.87, 0.875, "reeb: arcs",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t n = r.begin(); n < r.end(); ++n) {
                                    const i32 arc = g.node_arcs[n];
                                    if (arc == kNone) continue;
                                    const i32 hi = up_to[idx(up_off[n])];
                                    if (critical(hi)) g.arcs[idx(arc)][1] = hi;
                                }
                            });
    // (The tree's edges are arcs now: 12 bytes a node less beside the arcs' lists.)
    detail::release(below);
    detail::release(up_off);
    detail::release(up_to);
    const auto arc_of = [&](std::size_t n) -> std::int64_t { return g.node_arcs[n]; };
    g.arc_offsets.assign(arc_count + 1, 0);
    detail::count_by_key_parts(nn, g.arc_offsets, span(0.875, 0.885), arc_of);
    g.arc_nodes.resize(idx(g.arc_offsets.back()));
    detail::place_by_key_parts(
        nn, g.arc_offsets, span(0.885, 0.9), arc_of,
        [&](std::size_t n, std::size_t slot) { g.arc_nodes[slot] = static_cast<i32>(n); });
}

}  // namespace

bool contour_tree(const TriangleMesh& mesh, ReebGraph& g, const ProgressFn& progress,
                  Residency& memory) {
    memory.enter(Stage::reeb_links);
    const std::size_t nn = g.node_count();
    g.node_lower_links.assign(nn, 1);
    g.node_upper_links.assign(nn, 1);
    std::vector<char> general;
    std::vector<LinkReps> reps = link_components(mesh, g, g.node_lower_links, g.node_upper_links,
                                                 general, scaled_progress(progress, 0.2, 0.3));
    NodesAround around = nodes_around(mesh, g, reps);
    memory.stash(g.node_vertices);
    memory.stash(g.node_vertex_offsets);
    memory.stash(g.vertex_nodes);
    memory.stash(g.node_values);
    memory.enter(Stage::reeb_sweeps);

    JoinSplitTrees trees = join_and_split_trees(reps, around, progress);
    detail::release(reps);  // (16 bytes a node: what the arcs below are made beside)
    detail::release(around.nodes);
    detail::release(around.offsets);
    memory.enter(Stage::reeb_arcs);
    memory.take_back(g.node_values);
    memory.take_back(g.vertex_nodes);
    memory.take_back(g.node_vertex_offsets);
    memory.take_back(g.node_vertices);
    const auto components = std::count(trees.join_parent.begin(), trees.join_parent.end(), kNone);
    if (components == 1 ? !one_component_loop_free(mesh) : !loop_free_by_components(mesh))
        return false;
    report_progress(progress, 0.6, "reeb: join and split trees");
    std::vector<i32> attach = merge_trees(trees, progress);
    std::vector<i32> up_off, up_to;
    tree_edges(g, attach, up_off, up_to, progress);
    arcs_from_edges(g, attach, up_off, up_to, progress);
    report_progress(progress, 0.9, "reeb: arcs");
    count_general_links(mesh, g, general, scaled_progress(progress, 0.9, 1));
    return true;
}

}  // namespace terrain::reeb::internal
