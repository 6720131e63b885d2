// The result of the simplification (paper s.3.2: the simplified graph, and the field
// rewritten so that it agrees with it): every remaining node is numbered anew in the order of
// the old ones, an absorbed node's vertices join the node that finally took it (following
// forward links and the union-find sets of absorbed lists), each vertex takes its node's
// value, and the arcs that remain are listed with their regular nodes from the lower end up.

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <numeric>

#include "terrain/core/error.hpp"
#include "terrain/internal/core/disjoint_sets.hpp"
#include "terrain/internal/core/key_parts.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/release.hpp"
#include "working_graph.hpp"

namespace terrain::reeb::internal {

using detail::find_root;

std::vector<i32> WorkingGraph::final_codes(const ProgressFn& progress) {
    const std::size_t nl = regular_.size();
    using detail::PassProgress;
    // code[i]: for an absorbed node, the critical node that finally took it (nodes are
    // only absorbed into critical nodes); for a remaining node, -2 - its new id.
    // A listed node's forward: the fate of its set's root (kNone for a list still there).
    // (The passes over the nodes below run in parallel: their finds share the forests,
    // find_root_shared, and each writes its own entries.)
    const auto fate = [&](i32 f) {
        return f > -2 ? f : set_fate_[idx(detail::find_root_shared(set_parent_, -2 - f))];
    };
    // (Large blocks made a slice at a time, with heartbeats: their first touch is slow.)
    const auto made = [&](double at) { return PassProgress(progress, at, at, "simplify"); };
    // The critical nodes' codes first; a regular node's is written over its forward (read no
    // more), and joins the array once the rest of the working graph is gone: the working
    // graph and a code for every node at once were the peak of the simplification's memory.
    const std::size_t nc = idx(critical_count_);
    std::vector<i32> code;
    detail::assign_in_slices(code, nc, i32{0}, made(0), nc + nl);  // (room for all)
    constexpr std::size_t kGrain = std::size_t{1} << 14;
    detail::parallel_slices(nc, kGrain, progress, 0, 0.05, "simplify",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t k = r.begin(); k < r.end(); ++k)
                                    code[k] = fate(forward_of(critical_[k]));
                            });
    // (code[k] is written whole, with its root: a find through k reads its old link or the
    // root, both in k's tree.)
    detail::parallel_slices(
        nc, kGrain, progress, 0.05, 0.1, "simplify", [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t k = r.begin(); k < r.end(); ++k) {
                const i32 c = std::atomic_ref<i32>(code[k]).load(std::memory_order_relaxed);
                if (c == kNone) continue;
                const i32 root = detail::find_root_shared(code, c);
                std::atomic_ref<i32>(code[k]).store(root, std::memory_order_relaxed);
            }
        });
    detail::parallel_slices(
        nl, kGrain, progress, 0.1, 0.2, "simplify", [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t p = r.begin(); p < r.end(); ++p) {
                const i32 f = fate(regular_[p].forward);
                regular_[p].forward = f == kNone || code[idx(f)] == kNone ? f : code[idx(f)];
            }
        });
    return code;
}

WorkingGraph::Remains WorkingGraph::take_remains(const std::vector<i32>& code,
                                                 const ProgressFn& progress) {
    const std::size_t nc = idx(critical_count_), nl = regular_.size();
    const detail::PassProgress arcs(progress, 0.2, 0.3, "simplify");
    const auto code_of = [&](std::size_t i) { return i < nc ? code[i] : regular_[i - nc].forward; };
    Remains out;
    // (Counted first, the arrays made at their size: with a low area threshold half the
    // vertices remain, and growing them by doubling held the old array beside the new at
    // the simplification's peak of memory. The listed nodes are those that remain regular.)
    std::size_t count = 0, low = 0, critical = 0;
    for (std::size_t i = 0; i < nc + nl; ++i)
        if (code_of(i) == kNone) {
            ++count;
            low += i < nc;
            critical += i < nc && (critical_[i].flags & kCritical);
        }
    out.nodes = detail::RankedBits(nc + nl);
    out.values.reserve(count);
    out.critical.reserve(low);
    out.live_nodes.reserve(count - critical);
    for (std::size_t i = 0; i < nc + nl; ++i) {
        if (code_of(i) != kNone) continue;
        out.nodes.set(i);
        out.values.push_back(value(static_cast<i32>(i)));
        if (i >= nc) continue;
        RemainingCritical r;
        if (critical_[i].flags & kCritical) {
            const i32 d = down(static_cast<i32>(i)), u = up(static_cast<i32>(i));
            r.kind = d == 0 ? NodeKind::minimum : u == 0 ? NodeKind::maximum : NodeKind::saddle;
            r.changed = (critical_[i].flags & kModified) != 0;
            r.lower = static_cast<std::uint8_t>(std::min(d, 255));
            r.upper = static_cast<std::uint8_t>(std::min(u, 255));
        }
        out.critical.push_back(r);
    }
    out.nodes.count();
    auto& live_ends = out.live_ends;  // the arcs that live, in order
    auto& live_offsets = out.live_offsets;
    auto& live_nodes = out.live_nodes;
    const auto live = static_cast<std::size_t>(
        std::count_if(arcs_.begin(), arcs_.end(), [](const Arc& arc) { return arc.set != kNone; }));
    live_ends.reserve(live);
    live_offsets.reserve(live + 1);
    live_offsets.assign(1, 0);
    for (std::size_t a = 0; a < arcs_.size(); ++a) {
        arcs.at(a, arcs_.size());
        const Arc& arc = arcs_[a];
        if (arc.set == kNone) continue;
        live_ends.push_back(ends(static_cast<i32>(a)));
        for (i32 r = arc.head; r != kNone; r = next(r)) live_nodes.push_back(r);
        live_offsets.push_back(static_cast<i32>(live_nodes.size()));
    }
    return out;
}

std::vector<std::array<i32, 2>> WorkingGraph::renumber(std::vector<i32>& code,
                                                       std::vector<std::uint8_t>& gone,
                                                       const ProgressFn& progress) {
    const std::size_t nn = input_nodes_;
    using detail::PassProgress;
    // (Large blocks made a slice at a time, with heartbeats: their first touch is slow.)
    const auto made = [&](double at) { return PassProgress(progress, at, at, "simplify"); };
    const PassProgress numbers(progress, 0.3, 0.4, "simplify");
    // The remaining nodes are numbered in the order of the old ones; node_map_ takes each old
    // node's new node (first -2 - the node that took it, for the absorbed ones).
    std::vector<std::array<i32, 2>> kept;  // {old node, internal index} by new id
    detail::assign_in_slices(gone, nn, std::uint8_t{0}, made(0.3));
    for (std::size_t n = 0; n < nn; ++n) {
        numbers.at(n, nn);
        if (n + kAhead < nn) __builtin_prefetch(&code[idx(node_map_[n + kAhead])]);
        i32& c = code[idx(node_map_[n])];
        if (c != kNone) {
            node_map_[n] = -2 - c;
            gone[n] = 1;
            continue;
        }
        c = -2 - static_cast<i32>(kept.size());
        kept.push_back({static_cast<i32>(n), node_map_[n]});
        node_map_[n] = -2 - c;
    }
    for (std::size_t n = 0; n < nn; ++n)
        if (node_map_[n] < 0) node_map_[n] = -2 - code[idx(-2 - node_map_[n])];
    return kept;
}

void WorkingGraph::write_nodes_and_arcs(ReebGraph& out, const std::vector<std::array<i32, 2>>& kept,
                                        const Remains& remains, const std::vector<i32>& code) {
    const std::size_t count = kept.size();
    const auto& live_ends = remains.live_ends;
    const auto& live_offsets = remains.live_offsets;
    const auto& live_nodes = remains.live_nodes;
    out.node_values.resize(count);
    out.node_kinds.assign(count, NodeKind::regular);
    out.node_lower_links.assign(count, 1);
    out.node_upper_links.assign(count, 1);
    out.node_arcs.assign(count, kNone);
    for (std::size_t nid = 0; nid < count; ++nid) {
        const auto [n, i] = kept[nid];
        const std::size_t rank = remains.nodes.rank(idx(i));
        out.node_values[nid] = remains.values[rank];
        if (rank >= remains.critical.size()) continue;  // (a regular node's record)
        const RemainingCritical& at = remains.critical[rank];
        if (at.kind == NodeKind::regular) continue;
        out.node_kinds[nid] = at.kind;
        out.node_lower_links[nid] = at.changed ? at.lower : g_.node_lower_links[idx(n)];
        out.node_upper_links[nid] = at.changed ? at.upper : g_.node_upper_links[idx(n)];
    }
    if (owned_) {  // a graph handed over: what is read no more goes
        detail::release(owned_->node_lower_links);
        detail::release(owned_->node_upper_links);
    }
    // The arcs that remain, with their regular nodes from the lower end up.
    const auto new_id = [&](i32 i) { return -2 - code[idx(i)]; };
    out.arc_offsets.assign(1, 0);
    for (std::size_t k = 0; k < live_ends.size(); ++k) {
        const i32 id = static_cast<i32>(out.arcs.size());
        out.arcs.push_back({new_id(live_ends[k][0]), new_id(live_ends[k][1])});
        for (i32 p = live_offsets[k]; p < live_offsets[k + 1]; ++p) {
            const i32 nid = new_id(live_nodes[idx(p)]);
            out.arc_nodes.push_back(nid);
            out.node_arcs[idx(nid)] = id;
        }
        out.arc_offsets.push_back(static_cast<i32>(out.arc_nodes.size()));
    }
}

std::vector<i32> WorkingGraph::vertex_counts(std::size_t count) {
    const std::size_t nn = input_nodes_, nv = input_vertices_;
    // Each new node's vertex count.
    constexpr std::size_t kSmallCounts = std::size_t{1} << 16;
    std::vector<i32> size(count + 1, 0);
    if (lists_from_vertex_nodes_ && count <= kSmallCounts) {
        // (A simplified graph has few nodes: each thread counts into its own sizes, summed
        // after; the same integers in any order.)
        const auto& of = owned_->vertex_nodes;
        tbb::combinable<std::vector<i32>> counted([&] { return std::vector<i32>(count + 1, 0); });
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, std::size_t{1} << 16),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              auto& own = counted.local();
                              for (std::size_t v = r.begin(); v < r.end(); ++v)
                                  ++own[idx(node_map_[idx(of[v])]) + 1];
                          });
        counted.combine_each([&](const std::vector<i32>& own) {
            for (std::size_t i = 0; i < own.size(); ++i) size[i] += own[i];
        });
    } else if (lists_from_vertex_nodes_) {
        for (const i32 n : owned_->vertex_nodes) ++size[idx(node_map_[idx(n)]) + 1];
    } else {
        for (std::size_t n = 0; n < nn; ++n)
            size[idx(node_map_[n]) + 1] +=
                g_.node_vertex_offsets[n + 1] - g_.node_vertex_offsets[n];
    }
    return size;
}

void WorkingGraph::remake_vertex_lists(const ProgressFn& progress) {
    const std::size_t nn = input_nodes_, nv = input_vertices_;
    using detail::PassProgress;
    // (Large blocks made a slice at a time, with heartbeats: their first touch is slow.)
    const auto made = [&](double at) { return PassProgress(progress, at, at, "simplify"); };
    if (lists_from_vertex_nodes_) {
        // The input's vertex lists again, each ascending (a counting sort of the vertices by
        // node): what the graph handed over held.
        const PassProgress counted(progress, 0.4, 0.45, "simplify"),
            listed(progress, 0.45, 0.5, "simplify");
        auto& offsets = owned_->node_vertex_offsets;
        auto& listed_vertices = owned_->node_vertices;
        const auto& of = owned_->vertex_nodes;
        // (By parts of the nodes: in parallel, each list in vertex order, key_parts.hpp.)
        const auto node_of = [&](std::size_t v) -> std::int64_t { return of[v]; };
        detail::assign_in_slices(offsets, nn + 1, i32{0}, made(0.4));
        detail::count_by_key_parts(nv, offsets, counted, node_of);
        detail::assign_in_slices(listed_vertices, nv, i32{0}, made(0.45));
        detail::place_by_key_parts(
            nv, offsets, listed, node_of,
            [&](std::size_t v, std::size_t slot) { listed_vertices[slot] = static_cast<i32>(v); });
        detail::release(owned_->vertex_nodes);
    }
}

void WorkingGraph::write_vertices(SimplifyResult& result, bool rewrite_field,
                                  std::vector<i32>& size, const std::vector<std::uint8_t>& gone,
                                  const ProgressFn& progress) {
    const std::size_t nn = input_nodes_, nv = input_vertices_;
    ReebGraph& out = result.graph;
    using detail::PassProgress;
    // (Large blocks made a slice at a time, with heartbeats: their first touch is slow.)
    const auto made = [&](double at) { return PassProgress(progress, at, at, "simplify"); };
    // Vertices: grouped by new node, in the order of their old nodes (one pass in order), and
    // each vertex's new node, whether it was absorbed and its value (in parallel over the old
    // nodes, each vertex in one: its own entries), both at once.
    for (std::size_t i = 1; i < size.size(); ++i) size[i] += size[i - 1];
    out.node_vertex_offsets = size;
    detail::assign_in_slices(out.node_vertices, g_.node_vertices.size(), i32{0}, made(0.5));
    detail::assign_in_slices(out.vertex_nodes, nv, i32{0}, made(0.5));
    detail::assign_in_slices(result.absorbed, nv, std::uint8_t{0}, made(0.5));
    if (rewrite_field) detail::assign_in_slices(result.field, nv, 0.0f, made(0.5));
    tbb::task_group grouped;
    grouped.run([&] {
        for (std::size_t n = 0; n < nn; ++n) {
            const i32 nid = node_map_[n];
            for (i32 i = g_.node_vertex_offsets[n]; i < g_.node_vertex_offsets[n + 1]; ++i)
                out.node_vertices[idx(size[idx(nid)]++)] = g_.node_vertices[idx(i)];
        }
    });
    detail::parallel_slices(
        nn, std::size_t{1} << 12, progress, 0.5, 1.0, "simplify",
        [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t n = r.begin(); n < r.end(); ++n) {
                if (n + kAhead < r.end()) {
                    const i32 i = g_.node_vertex_offsets[n + kAhead];
                    if (i < g_.node_vertex_offsets[n + kAhead + 1])
                        __builtin_prefetch(&out.vertex_nodes[idx(g_.node_vertices[idx(i)])], 1);
                }
                const i32 nid = node_map_[n];
                const float value = out.node_values[idx(nid)];
                for (i32 i = g_.node_vertex_offsets[n]; i < g_.node_vertex_offsets[n + 1]; ++i) {
                    const i32 v = g_.node_vertices[idx(i)];
                    out.vertex_nodes[idx(v)] = nid;
                    result.absorbed[idx(v)] = gone[n];
                    if (rewrite_field) result.field[idx(v)] = value;
                }
            }
        });
    grouped.wait();
}

void WorkingGraph::write_result(SimplifyResult& result, bool rewrite_field,
                                const ProgressFn& progress) {
    const std::size_t nn = input_nodes_, nl = regular_.size();
    if (memory_) memory_->enter(Stage::simplify_output);
    // Its passes: the fates (0 to 0.2), the arcs (to 0.3), the new numbers (to 0.4), the
    // input's vertex lists made again (to 0.5), the vertices and their values (to 1).
    std::vector<i32> code = final_codes(progress);
    Remains remains = take_remains(code, progress);
    release_working_graph();
    // The regular nodes' codes join the array (in its room), and their records go, their
    // pages given back behind the copy.
    {
        detail::PagesBehind behind(regular_.data());
        for (std::size_t p = 0; p < nl; ++p) {
            code.push_back(regular_[p].forward);
            if ((p & 0xffff) == 0) behind.before(regular_.data() + p);
        }
    }
    detail::release(regular_);
    if (memory_) {
        memory_->take_back(node_map_);
        if (node_map_.size() != nn)
            throw Error("simplify", "the new numbers came back with the wrong size");
    }
    std::vector<std::uint8_t> gone;  // old nodes absorbed by another
    auto kept = renumber(code, gone, progress);
    const std::size_t count = kept.size();
    if (count != remains.values.size())
        throw Error("simplify", "internal: the remaining nodes are not one an old node");
    write_nodes_and_arcs(result.graph, kept, remains, code);
    detail::release(code);
    detail::release(kept);
    remains.nodes = detail::RankedBits();
    detail::release(remains.values);
    detail::release(remains.critical);
    detail::release(remains.live_ends);
    detail::release(remains.live_offsets);
    detail::release(remains.live_nodes);
    const std::size_t nv = input_vertices_;
    if (memory_ && lists_from_vertex_nodes_) {
        memory_->take_back(owned_->vertex_nodes);
        if (owned_->vertex_nodes.size() != nv)
            throw Error("simplify", "the vertices' nodes came back with the wrong size");
    }
    std::vector<i32> size = vertex_counts(count);
    remake_vertex_lists(progress);
    report_progress(progress, 0.5, "simplify");
    write_vertices(result, rewrite_field, size, gone, progress);
    detail::release(size);
    detail::release(gone);
    detail::release(node_map_);
    if (owned_) *owned_ = ReebGraph{};
}

}  // namespace terrain::reeb::internal
