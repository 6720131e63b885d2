#pragma once
// Private: the working graph of the simplification (simplify.cpp), a mutable copy of a Reeb
// graph laid out for few cache misses. Nodes are numbered anew: first the nodes that are in no
// arc's list (the critical ones, the only possible arc ends), in their order, then the listed
// regular nodes in the order of arc_nodes, so that each list starts out contiguous. A
// critical node is one 64-byte record (value, area, flags, arc counts and its arcs: up to 8
// in the record, more in a run of a shared arena); regular nodes sit in doubly linked lists,
// one per arc, sorted by value. A list absorbed whole is never walked: its area moves at once
// and its nodes learn where they went in the output, through union-find sets of lists (see
// Arc). The cancellation rules are in cancellation.cpp, the result in simplify_output.cpp.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "../core/indices.hpp"
#include "arc_measures.hpp"
#include "terrain/reeb/simplify.hpp"

namespace terrain::reeb::internal {

using detail::i32;
using detail::idx;
using detail::kNone;

// Passes that gather from or scatter to random places start fetching them this many steps
// ahead.
inline constexpr std::size_t kAhead = 16;

class WorkingGraph {
  public:
    // Throws terrain::Error when an arc's list holds an arc end or a node of another list.
    WorkingGraph(const TriangleMesh& mesh, const ReebGraph& g);

    // The simplified graph and the rewritten field (simplify_output.cpp).
    void write_result(SimplifyResult& result);
    // The bytes it holds now: records, arc runs (freed ones included), list sets.
    std::size_t working_bytes() const;

  protected:
    // A critical node (one of the first critical_count_), in one cache line: its fields and its
    // `size` arcs, the newest last, with room for kInline << shift (see arc_run()).
    static constexpr i32 kInline = 8;
    struct alignas(64) CriticalNode {
        double area = 0;  // its vertices' and its absorbed nodes' area
        float value = 0;
        i32 forward = kNone;  // the node that absorbed it
        i32 size = 0;
        i32 down = 0;            // its arcs whose upper end it is
        i32 offset = 0;          // its run in arena_ when shift > 0
        std::uint8_t shift = 0;  // room for kInline << shift arcs
        std::uint8_t flags = 0;  // kCritical, kModified
        // Its run while shift == 0; once it is regular (no arcs), its previous and next node
        // in its arc's list.
        std::array<i32, kInline> own{};
    };
    static_assert(sizeof(CriticalNode) == 64);
    // A node's `forward`: the critical node that absorbed it; for a node in a list, -2 - the
    // set of its list (see Arc::set); kNone for a critical node.
    struct RegularNode {
        double area = 0;
        float value = 0;
        i32 forward = kNone;
        i32 prev = kNone, next = kNone;  // its neighbours in its arc's list
    };
    static constexpr std::uint32_t kNotQueued = ~std::uint32_t{0};  // no persistence's bits
    // An arc's regular nodes form a set: at first the arc's own (named by its id); an arc
    // merged into another joins its set; a list absorbed whole gives its set a fate, the node
    // that took it, and its arc a new set. Lists are thus absorbed at once, and the nodes
    // learn their fate in the output.
    struct Arc {
        std::array<i32, 2> end{kNone, kNone};  // {lower, upper}
        i32 head = kNone, tail = kNone;        // regular nodes, lower to upper
        double area = 0;                       // area of the regular nodes' vertices
        std::uint32_t queued = kNotQueued;     // its key's high half while queued
        i32 set = kNone;                       // its nodes' set; kNone once the arc is gone
    };
    static_assert(sizeof(Arc) == 32);
    static constexpr std::uint8_t kCritical = 1, kModified = 2;
    // Any node's fields (a critical node's list neighbours are used once it is regular).
    double& area(i32 n) {
        return n < critical_count_ ? critical_[idx(n)].area
                                   : regular_[idx(n - critical_count_)].area;
    }
    float value(i32 n) const {
        return n < critical_count_ ? critical_[idx(n)].value
                                   : regular_[idx(n - critical_count_)].value;
    }
    i32& forward(i32 n) {
        return n < critical_count_ ? critical_[idx(n)].forward
                                   : regular_[idx(n - critical_count_)].forward;
    }
    i32& prev(i32 n) {
        return n < critical_count_ ? critical_[idx(n)].own[0]
                                   : regular_[idx(n - critical_count_)].prev;
    }
    i32& next(i32 n) {
        return n < critical_count_ ? critical_[idx(n)].own[1]
                                   : regular_[idx(n - critical_count_)].next;
    }

    // A critical node's arcs, the newest last: in its record while they fit, else in the arena.
    i32* arc_run(CriticalNode& c) { return c.shift == 0 ? c.own.data() : arena_.data() + c.offset; }
    const i32* arc_run(const CriticalNode& c) const {
        return c.shift == 0 ? c.own.data() : arena_.data() + c.offset;
    }
    // The arcs at a critical node, newest first.
    template <class F>
    void for_each_arc(i32 n, F&& f) const {
        const CriticalNode& c = critical_[idx(n)];
        const i32* r = arc_run(c);
        for (i32 i = c.size - 1; i >= 0; --i) f(r[i]);
    }
    void arcs_at(i32 n, std::vector<i32>& out) const {
        out.clear();
        for_each_arc(n, [&](i32 a) { out.push_back(a); });
    }
    // Arc a joins node n. A full run moves to a run with twice the room: a freed run of that
    // size if there is one, else a new one at the arena's end; the old run is freed. The
    // arena thus holds at most the runs of the nodes that have arcs now (plus freed runs
    // waiting for reuse), however often arcs move between nodes: moving a high-degree node's
    // arcs to a new node at every cancellation, as the degenerate extrema of noisy closed
    // surfaces do, once grew it without bound (past 2^31 entries on a 66 M pixel global grid).
    void link(i32 a, i32 n) {
        CriticalNode& c = critical_[idx(n)];
        if (c.size == kInline << c.shift) {
            const std::uint8_t shift = static_cast<std::uint8_t>(c.shift + 1);
            const i32 offset = take_run(shift);
            std::copy_n(arc_run(c), c.size, arena_.data() + offset);
            release_run(c);
            c.offset = offset;
            c.shift = shift;
        }
        arc_run(c)[c.size++] = a;
    }
    // Arc a leaves node n (the newest of its entries there, for an arc with both ends at n).
    void unlink(i32 a, i32 n) {
        CriticalNode& c = critical_[idx(n)];
        if (c.size == 1) {  // its only arc
            c.size = 0;
            release_run(c);
            return;
        }
        i32* const last = arc_run(c) + c.size;
        i32* it = last - 1;
        while (*it != a) --it;
        for (; it + 1 != last; ++it) *it = *(it + 1);
        --c.size;
    }
    // A node left with no arcs gives its run back (its arcs go in its record again, and its
    // record may hold its list neighbours).
    void release_run(CriticalNode& c) {
        if (c.shift == 0) return;
        free_runs_[c.shift].push_back(c.offset);
        c.shift = 0;
    }
    // A run with room for kInline << shift arcs: a freed one, or a new one at the arena's end.
    i32 take_run(std::uint8_t shift);

    // Arcs below and above a critical node: its arcs ending there as the upper / lower end
    // (`down` is updated wherever an arc end moves or an arc turns around).
    i32 degree(i32 n) const { return critical_[idx(n)].size; }
    i32 down(i32 n) const { return critical_[idx(n)].down; }
    i32 up(i32 n) const { return critical_[idx(n)].size - critical_[idx(n)].down; }
    bool extremum(i32 n) const { return down(n) == 0 || up(n) == 0; }
    // The measures of arc a (arc_measures.hpp).
    float persistence(i32 a) const {
        const Arc& arc = arcs_[idx(a)];
        return internal::persistence(value(arc.end[0]), value(arc.end[1]));
    }
    double area_ratio(i32 a) const {
        const Arc& arc = arcs_[idx(a)];
        const i32 lo = arc.end[0], hi = arc.end[1];
        const auto add_list_area = [&](double sum) { return sum + arc.area; };
        return internal::area_ratio(critical_[idx(lo)].area, degree(lo), critical_[idx(hi)].area,
                                    degree(hi), add_list_area, total_area_);
    }
    // Whether another arc joins the same two nodes as arc a (a loop of the graph).
    bool has_parallel_arc(i32 a) const {
        const Arc& arc = arcs_[idx(a)];
        const i32 n = degree(arc.end[0]) <= degree(arc.end[1]) ? arc.end[0] : arc.end[1];
        if (degree(n) == 1) return false;  // a is its only arc
        bool found = false;
        for_each_arc(n, [&](i32 b) {
            if (b == a) return;
            const auto& e = arcs_[idx(b)].end;
            found |= (e[0] == arc.end[0] && e[1] == arc.end[1]) ||
                     (e[0] == arc.end[1] && e[1] == arc.end[0]);
        });
        return found;
    }
    // Node n's vertices (and everything already forwarded to it) join the critical node keep.
    void absorb(i32 n, i32 keep) {
        forward(n) = keep;
        critical_[idx(keep)].area += area(n);
    }
    // The regular nodes of an arc join keep, their area at once (the output tells them);
    // the arc, if it lives on, starts a new set.
    void absorb_list(Arc& arc, i32 keep, bool lives) {
        if (arc.head != kNone) {
            critical_[idx(keep)].area += arc.area;
            set_fate_[idx(arc.set)] = keep;
            if (lives) {
                arc.set = static_cast<i32>(set_fate_.size());
                set_fate_.push_back(kNone);
                set_parent_.push_back(kNone);
            }
        }
        arc.head = arc.tail = kNone;
        arc.area = 0;
    }

    const ReebGraph& g_;
    // Each node of g_: its number here (then, in write_result, its node in the result).
    std::vector<i32> node_map_;
    i32 critical_count_ = 0;  // critical nodes: 0 .. critical_count_ - 1
    std::vector<CriticalNode> critical_;
    std::vector<RegularNode> regular_;  // node critical_count_ + i is regular_[i]
    std::vector<i32> arena_;
    std::array<std::vector<i32>, 32> free_runs_;  // freed runs by shift
    std::size_t arena_peak_ = 0;                  // the arena's largest size, entries
    double total_area_ = 0;
    std::vector<i32> set_parent_;  // of each set, kNone for a root (an arc's current set)
    std::vector<i32> set_fate_;    // of each root set: the node that absorbed it, or kNone
    std::vector<Arc> arcs_;
};

}  // namespace terrain::reeb::internal
