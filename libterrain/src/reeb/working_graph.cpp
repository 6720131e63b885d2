// The working graph of the simplification: the Reeb graph copied into the layout that
// working_graph.hpp describes (critical nodes first, one record each; the lists' regular
// nodes in list order; each arc's list its own set at first).

#include "working_graph.hpp"

#include <algorithm>
#include <atomic>
#include <limits>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "terrain/core/error.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/ranked_bits.hpp"
#include "terrain/internal/core/release.hpp"

namespace terrain::reeb::internal {

i32 WorkingGraph::take_run(std::uint8_t shift) {
    const std::size_t room = std::size_t{kInline} << shift;
    auto& freed = free_runs_[shift];
    if (!freed.empty()) {
        const i32 offset = freed.back();
        freed.pop_back();
        return offset;
    }
    const std::size_t offset = arena_.size();
    if (offset + room > static_cast<std::size_t>(std::numeric_limits<i32>::max()))
        throw Error("simplify", "a node has more arcs than the working graph can hold (2^31)");
    arena_.resize(offset + room);
    arena_peak_ = std::max(arena_peak_, arena_.size());
    return static_cast<i32>(offset);
}

void WorkingGraph::make_big(i32 n) {
    CriticalNode& c = critical_[idx(n)];
    std::vector<i32> arcs;
    arcs_at(n, arcs);
    std::reverse(arcs.begin(), arcs.end());
    release_run(c);
    i32 slot;
    if (!free_big_.empty()) {
        slot = free_big_.back();
        free_big_.pop_back();
    } else {
        slot = static_cast<i32>(big_.size());
        big_.emplace_back();
    }
    c.slot[0] = slot;
    c.flags = static_cast<std::uint8_t>((c.flags | kBig) & ~kPending);
    for (const i32 b : arcs) big_insert(n, b);
}

void WorkingGraph::release_big(CriticalNode& c) {
    BigNode& b = big_[idx(c.slot[0])];
    b = BigNode{};
    free_big_.push_back(c.slot[0]);
    c.flags = static_cast<std::uint8_t>(c.flags & ~(kBig | kPending));
    c.slot[0] = 0;
}

WorkingGraph::BigNode::Keys WorkingGraph::keys_of(i32 b, i32 n) const {
    const auto& e = ends(b);
    const Arc& arc = arcs_[idx(b)];
    BigNode::Keys k;
    k.side = e[1] == n ? 0 : 1;  // 0: n is the upper end, the arc is below it
    const i32 far = k.side == 0 ? e[0] : e[1];
    k.far = value(far);
    const i32 nearest = k.side == 0 ? arc.tail : arc.head;
    k.near = nearest == kNone ? k.far : value(nearest);
    k.ext = extremum(far);
    return k;
}

void WorkingGraph::big_insert(i32 n, i32 b) {
    BigNode& big_node = big_of(n);
    const BigNode::Keys k = keys_of(b, n);
    if (!big_node.keys.emplace(b, k).second)
        throw Error("simplify", "internal: arc " + std::to_string(b) + " joined a node twice");
    const float sign = k.side == 0 ? -1.0f : 1.0f;
    big_node.far[k.side].emplace(sign * k.far, b);
    big_node.near[k.side].emplace(sign * k.near, b);
    if (k.ext) big_node.ext[k.side].emplace(sign * k.far, b);
    const i32 other = other_end(b, n);
    if (big(other)) {
        big_node.bb.insert(b);
        big_of(other).bb.insert(b);
    }
}

void WorkingGraph::big_erase(i32 n, i32 b) {
    BigNode& big_node = big_of(n);
    const auto it = big_node.keys.find(b);
    if (it == big_node.keys.end()) return;
    const BigNode::Keys k = it->second;
    const float sign = k.side == 0 ? -1.0f : 1.0f;
    big_node.far[k.side].erase({sign * k.far, b});
    big_node.near[k.side].erase({sign * k.near, b});
    if (k.ext) big_node.ext[k.side].erase({sign * k.far, b});
    big_node.keys.erase(it);
    big_node.bb.erase(b);
}

bool WorkingGraph::refresh(i32 n, i32 b) {
    if (!big(n)) return false;
    BigNode& big_node = big_of(n);
    const auto it = big_node.keys.find(b);
    if (it == big_node.keys.end()) return false;
    if (keys_of(b, n) == it->second) return false;
    big_erase(n, b);
    big_insert(n, b);
    return true;
}

void WorkingGraph::release_working_graph() {
    detail::release(critical_);
    detail::release(arena_);
    for (auto& f : free_runs_) detail::release(f);
    detail::release(set_parent_);
    detail::release(set_fate_);
    detail::release(arcs_);
    detail::release(big_);
    detail::release(free_big_);
    detail::release(pending_big_);
}

std::size_t WorkingGraph::working_bytes() const {
    std::size_t freed = 0;
    for (const auto& f : free_runs_) freed += f.capacity() * sizeof(i32);
    // A big node's arc: three set entries and a map entry, about 48 bytes each.
    for (const BigNode& b : big_) freed += b.keys.size() * 4 * 48 + b.bb.size() * 48;
    // (The arena and the sets by their size: their room is reserved ahead, untouched.)
    return critical_.capacity() * sizeof(CriticalNode) + regular_.capacity() * sizeof(RegularNode) +
           arcs_.capacity() * sizeof(Arc) + arena_.size() * sizeof(i32) + freed +
           (set_parent_.size() + set_fate_.size() + node_map_.capacity()) * sizeof(i32);
}

namespace {

// The summed area of node n's vertices, added in increasing vertex order (as a sweep over
// the vertices would add them). `sorted` turns false when the node's list is not ascending.
double node_area(const TriangleMesh& mesh, const ReebGraph& g, std::size_t n,
                 std::vector<i32>& scratch, bool& sorted) {
    const i32* v = g.node_vertices.data() + g.node_vertex_offsets[n];
    const std::size_t count = idx(g.node_vertex_offsets[n + 1] - g.node_vertex_offsets[n]);
    if (count > 1 && !std::is_sorted(v, v + count)) {
        sorted = false;
        scratch.assign(v, v + count);
        std::sort(scratch.begin(), scratch.end());
        v = scratch.data();
    }
    double s = 0;
    for (std::size_t i = 0; i < count; ++i)
        s += mesh.vertex_areas.empty() ? 1.0 : mesh.vertex_areas[idx(v[i])];
    return s;
}

// Whether every node's vertex list is ascending (node_area's order).
bool lists_ascending(const ReebGraph& g) {
    for (std::size_t n = 0; n + 1 < g.node_vertex_offsets.size(); ++n)
        if (!std::is_sorted(g.node_vertices.data() + g.node_vertex_offsets[n],
                            g.node_vertices.data() + g.node_vertex_offsets[n + 1]))
            return false;
    return true;
}

}  // namespace

void WorkingGraph::number_listed_nodes(const ReebGraph& g, const ProgressFn& progress) {
    using detail::PassProgress;
    const std::size_t nn = g.node_count(), na = g.arc_count(), nl = g.arc_nodes.size();
    // node_map_[n]: arc ends marked, the other regular nodes of the lists by their position in
    // arc_nodes; then the new numbers.
    constexpr i32 kEnd = -2;
    detail::assign_in_slices(node_map_, nn, kNone, PassProgress(progress, 0, 0.03, "simplify"));
    // (Both passes in parallel: every arc end takes the same mark, every listed node its own
    // position, stored without a lock. A node listed twice or also an arc end is found by a
    // second look, and the serial pass then names the first such node, as it always did.)
    constexpr std::size_t kGrain = std::size_t{1} << 14;
    const auto store = [](i32& to, i32 value) {
        std::atomic_ref<i32>(to).store(value, std::memory_order_relaxed);
    };
    const auto load = [](i32& from) {
        return std::atomic_ref<i32>(from).load(std::memory_order_relaxed);
    };
    detail::parallel_slices(na, kGrain, progress, 0.03, 0.03, "simplify",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t a = r.begin(); a < r.end(); ++a)
                                    for (const i32 e : g.arcs[a]) store(node_map_[idx(e)], kEnd);
                            });
    // (A critical node in a list keeps its neighbours in its record, which an arc end needs
    // for its arcs.)
    const auto listed_regular = [&](std::size_t p) {
        const i32 r = g.arc_nodes[p];
        return g.node_kinds[idx(r)] == NodeKind::regular && load(node_map_[idx(r)]) != kEnd;
    };
    std::atomic<bool> invalid{false};
    detail::parallel_slices(nl, kGrain, progress, 0.03, 0.07, "simplify",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t p = r.begin(); p < r.end(); ++p) {
                                    if (!listed_regular(p)) {
                                        if (load(node_map_[idx(g.arc_nodes[p])]) == kEnd)
                                            invalid = true;
                                        continue;
                                    }
                                    store(node_map_[idx(g.arc_nodes[p])], static_cast<i32>(p));
                                }
                            });
    detail::parallel_slices(
        nl, kGrain, progress, 0.07, 0.1, "simplify", [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t p = r.begin(); p < r.end(); ++p)
                if (listed_regular(p) && node_map_[idx(g.arc_nodes[p])] != static_cast<i32>(p))
                    invalid = true;
        });
    if (invalid) {  // the serial pass, for its message
        for (std::size_t p = 0; p < nl; ++p)
            if (listed_regular(p)) node_map_[idx(g.arc_nodes[p])] = kNone;
        for (std::size_t p = 0; p < nl; ++p) {
            const i32 r = g.arc_nodes[p];
            if (node_map_[idx(r)] != kNone)
                throw Error("simplify", "the graph is not valid: node " + std::to_string(r) +
                                            " is an arc end or in two arcs' lists");
            if (g.node_kinds[idx(r)] != NodeKind::regular) continue;
            node_map_[idx(r)] = static_cast<i32>(p);
        }
    }
}

bool WorkingGraph::copy_nodes(const TriangleMesh& mesh, const ReebGraph& g,
                              const detail::RankedBits& critical_nodes, ReebGraph* owned,
                              std::size_t wave, const ProgressFn& progress) {
    using detail::PassProgress;
    const PassProgress nodes(progress, 0.25, 0.6, "simplify");
    const std::size_t nn = g.node_count(), nl = g.arc_nodes.size();
    constexpr std::size_t kGrain = std::size_t{1} << 14;
    // The regular nodes' records are written in list order, at random: made whole first (a
    // slice at a time: a large block's first touch is slow, docs/performance.md). The
    // critical nodes' are written in order by the nodes' pass: their pages are touched as it
    // goes, while the input's node arrays it has read are given back behind it.
    detail::assign_in_slices(regular_, nl, RegularNode{},
                             PassProgress(progress, 0.1, 0.25, "simplify"));
    critical_.reserve(idx(critical_count_));
    // Whether write_result makes the vertex lists again from the vertices' nodes (every list
    // ascending): then the lists are not read after this pass either.
    if (owned)
        lists_from_vertex_nodes_ =
            owned->vertex_nodes.size() == input_vertices_ && lists_ascending(g);
    detail::PagesBehind values_behind, kinds_behind, offsets_behind, lists_behind;
    if (owned) {
        values_behind = detail::PagesBehind(g.node_values.data());
        kinds_behind = detail::PagesBehind(g.node_kinds.data());
        if (lists_from_vertex_nodes_) {
            offsets_behind = detail::PagesBehind(g.node_vertex_offsets.data());
            lists_behind = detail::PagesBehind(g.node_vertices.data());
        }
    }
    // The nodes a wave at a time. On every thread: each node's area (its vertices' areas
    // gathered), and the regular nodes' records (each written by its own node). Then, in
    // order: the areas summed (the same additions in the same order as one pass in order),
    // and the critical nodes' records appended, their pages touched first on every thread.
    total_area_ = 0;
    std::atomic<bool> all_sorted{true};  // every node's vertex list ascending
    std::vector<double> wave_area(std::min(nn, wave));
    i32 k = 0;
    for (std::size_t n0 = 0; n0 < nn; n0 += wave) {
        const std::size_t n1 = std::min(nn, n0 + wave);
        nodes.at(n0, nn);
        // (what nodes before n0 held is read for the last time)
        values_behind.before(g.node_values.data() + n0);
        kinds_behind.before(g.node_kinds.data() + n0);
        offsets_behind.before(g.node_vertex_offsets.data() + n0);
        lists_behind.before(g.node_vertices.data() + g.node_vertex_offsets[n0]);
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(n0, n1, kGrain),
            [&](const tbb::blocked_range<std::size_t>& r) {
                std::vector<i32> scratch;
                bool sorted = true;
                for (std::size_t n = r.begin(); n < r.end(); ++n) {
                    if (n + kAhead < r.end()) {
                        const std::size_t m = n + kAhead;
                        const i32 i = g.node_vertex_offsets[m];
                        if (!mesh.vertex_areas.empty() && i < g.node_vertex_offsets[m + 1])
                            __builtin_prefetch(&mesh.vertex_areas[idx(g.node_vertices[idx(i)])]);
                        if (node_map_[m] >= 0) __builtin_prefetch(&regular_[idx(node_map_[m])], 1);
                    }
                    const double area = node_area(mesh, g, n, scratch, sorted);
                    wave_area[n - n0] = area;
                    if (node_map_[n] >= 0) {
                        RegularNode& node = regular_[idx(node_map_[n])];
                        node.area = area;
                        node.value = g.node_values[n];
                        node_map_[n] += critical_count_;
                    }
                }
                if (!sorted) all_sorted = false;
            });
        const std::size_t critical_here =
            critical_nodes.rank(n1 - 1) + critical_nodes.test(n1 - 1) - critical_.size();
        detail::touch_pages(critical_.data() + critical_.size(),
                            critical_here * sizeof(CriticalNode));
        for (std::size_t n = n0; n < n1; ++n) {
            const double area = wave_area[n - n0];
            total_area_ += area;
            if (node_map_[n] >= 0) continue;
            CriticalNode& c = critical_.emplace_back();
            c.area = area;
            c.value = g.node_values[n];
            c.flags = g.node_kinds[n] != NodeKind::regular ? kCritical : 0;
            node_map_[n] = k++;
        }
    }
    const bool sorted = all_sorted;
    detail::release(wave_area);
    total_area_ = mesh_area_or_one(total_area_);
    return sorted;
}

void WorkingGraph::release_copied_nodes(ReebGraph& owned, bool sorted) {
    detail::release(owned.node_values);
    detail::release(owned.node_kinds);
    // The vertex lists or the vertices' nodes, whichever write_result will not read.
    if (lists_from_vertex_nodes_ != (sorted && owned.vertex_nodes.size() == input_vertices_))
        throw Error("simplify", "internal: the vertex lists' order changed during the copy");
    if (lists_from_vertex_nodes_) {
        detail::release(owned.node_vertices);
        detail::release(owned.node_vertex_offsets);
    } else {
        detail::release(owned.vertex_nodes);
    }
    // Read again only by write_result: they may wait elsewhere through the peak.
    if (lists_from_vertex_nodes_ && memory_) memory_->stash(owned.vertex_nodes);
}

void WorkingGraph::copy_arcs(const ReebGraph& g, const detail::RankedBits& critical_nodes,
                             ReebGraph* owned, std::size_t wave, const ProgressFn& progress) {
    using detail::PassProgress;
    const PassProgress arcs(progress, 0.7, 1, "simplify");
    const std::size_t na = g.arc_count();
    constexpr std::size_t kGrain = std::size_t{1} << 14;
    const auto critical_number = [&](i32 n) {
        return static_cast<i32>(critical_nodes.rank(idx(n)));
    };
    // Arc a joins its lower then its upper end, a in order. As with the critical nodes, the
    // arcs' records are written in order into a block reserved, not filled, first, and the
    // input's arcs, offsets and listed nodes go back to the system behind the pass: the end
    // of this pass is the simplification's peak of memory.
    arcs_.reserve(na);
    // (The arena's room reserved ahead, untouched until used: runs taken through the
    // cancellations then copy no arena, which held its old and its new block at once.)
    arena_.reserve(2 * na);
    report_progress(progress, 0.7, "simplify");
    detail::PagesBehind ends_behind, offsets_behind_a, listed_behind;
    if (owned) {
        ends_behind = detail::PagesBehind(g.arcs.data());
        offsets_behind_a = detail::PagesBehind(g.arc_offsets.data());
        listed_behind = detail::PagesBehind(g.arc_nodes.data());
    }
    // A wave of arcs at a time: their records' pages touched on every thread; each arc's ends
    // and list on every thread (each listed node is in one list, and lists hold no arc end);
    // then the arcs join their ends in arc order (a node's arcs in the order one pass made).
    for (std::size_t a0 = 0; a0 < na; a0 += wave) {
        const std::size_t a1 = std::min(na, a0 + wave);
        arcs.at(a0, na);
        // (what arcs before a0 held is read for the last time)
        ends_behind.before(g.arcs.data() + a0);
        offsets_behind_a.before(g.arc_offsets.data() + a0);
        listed_behind.before(g.arc_nodes.data() + g.arc_offsets[a0]);
        detail::touch_pages(arcs_.data() + a0, (a1 - a0) * sizeof(Arc));
        arcs_.resize(a1);
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(a0, a1, kGrain),
            [&](const tbb::blocked_range<std::size_t>& range) {
                for (std::size_t a = range.begin(); a < range.end(); ++a) {
                    if (a + kAhead < range.end())
                        for (const i32 e : g.arcs[a + kAhead]) critical_nodes.prefetch(idx(e));
                    Arc& arc = arcs_[a];
                    arc.end = {critical_number(g.arcs[a][0]), critical_number(g.arcs[a][1])};
                    arc.set = static_cast<i32>(a);
                    for (i32 p = g.arc_offsets[a]; p < g.arc_offsets[a + 1]; ++p) {
                        const i32 listed = g.arc_nodes[idx(p)];
                        const i32 r = critical_nodes.test(idx(listed)) ? critical_number(listed)
                                                                       : critical_count_ + p;
                        set_forward(r, -2 - arc.set);
                        if (arc.tail == kNone) {
                            arc.head = r;
                        } else {
                            next(arc.tail) = r;
                            prev(r) = arc.tail;
                        }
                        arc.tail = r;
                        arc.area += area(r);
                    }
                }
            });
        for (std::size_t a = a0; a < a1; ++a) {
            if (a + kAhead < a1)
                for (const i32 e : arcs_[a + kAhead].end) __builtin_prefetch(&critical_[idx(e)], 1);
            const Arc& arc = arcs_[a];
            for (const i32 e : arc.end) link(static_cast<i32>(a), e);
            ++critical_[idx(arc.end[1])].down;
        }
    }
    if (owned) {  // the arcs are copied
        detail::release(owned->arcs);
        detail::release(owned->arc_offsets);
        detail::release(owned->arc_nodes);
    }
}

WorkingGraph::WorkingGraph(const TriangleMesh& mesh, const ReebGraph& g, i32 big_degree,
                           const ProgressFn& progress, ReebGraph* owned, Residency* memory,
                           std::size_t wave)
    : g_(g),
      input_nodes_(g.node_count()),
      input_vertices_(g.vertex_nodes.size()),
      big_degree_(big_degree) {
    // Its passes: the lists (0 to 0.1), the nodes (to 0.6), the arcs (to 1), each with its
    // large blocks made a slice at a time (their first touch is slow, docs/performance.md).
    using detail::PassProgress;
    const std::size_t nn = g.node_count(), na = g.arc_count();
    owned_ = owned;
    memory_ = owned ? memory : nullptr;
    if (memory) memory->enter(Stage::simplify_nodes);
    if (owned) detail::release(owned->node_arcs);  // not read here
    number_listed_nodes(g, progress);
    // The critical nodes (arc ends, and critical nodes in lists) as a bit each: a critical
    // node's new number is its rank among them, which the arcs' pass reads instead of
    // node_map_ (4 bytes a node, parked before it).
    detail::RankedBits critical_nodes(nn);
    for (std::size_t n = 0; n < nn; ++n)
        if (node_map_[n] < 0) critical_nodes.set(n);
    critical_nodes.count();
    critical_count_ = static_cast<i32>(critical_nodes.members());
    wave = std::max<std::size_t>(1, wave);
    const bool sorted = copy_nodes(mesh, g, critical_nodes, owned, wave, progress);
    // The mesh's areas are read no more (before the arcs: their copy's end is the peak).
    if (memory) memory->enter(Stage::simplify_arcs);
    // The new numbers are read again only by write_result, once the working graph is freed:
    // they may wait elsewhere through the arcs' copy (the peak) and the cancellations.
    if (memory_) memory_->stash(node_map_);
    if (owned) release_copied_nodes(*owned, sorted);  // the nodes are copied
    copy_arcs(g, critical_nodes, owned, wave, progress);
    // The lists' sets, made once the input's arcs are freed (the copy's end is the peak of
    // the simplification's memory), with room for as many new sets again, reserved and not
    // touched: a set made by a cancellation then copies no array (a vector growing copies
    // itself, and holds its old and its new block at once).
    detail::assign_in_slices(set_parent_, na, kNone, PassProgress(progress, 1, 1, "simplify"),
                             2 * na);
    detail::assign_in_slices(set_fate_, na, kNone, PassProgress(progress, 1, 1, "simplify"),
                             2 * na);
}

}  // namespace terrain::reeb::internal
