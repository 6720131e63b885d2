#pragma once
// Private: the working graph of the simplification (simplify.cpp), a mutable copy of a Reeb
// graph laid out for few cache misses. Nodes are numbered anew: first the nodes that are in no
// arc's list (the critical ones, the only possible arc ends), in their order, then the listed
// regular nodes in the order of arc_nodes, so that each list starts out contiguous. A
// critical node is one 32-byte record (value, area, flags, arc counts and its arcs: up to 3
// in the record, more in a run of a shared arena); regular nodes sit in doubly linked lists,
// one per arc, sorted by value. A list absorbed whole is never walked: its area moves at once
// and its nodes learn where they went in the output, through union-find sets of lists (see
// Arc). The cancellation rules are in cancellation.cpp, the result in simplify_output.cpp.
//
// A node with many arcs is "big" (kBig; the degenerate extrema of noisy closed surfaces
// reach tens of thousands of arcs and move from node to node): its arcs sit in ordered sets
// (BigNode) instead of a run, by their far end's value and by the value nearest to the node
// along the arc, so that a cancellation touches only the arcs it changes. A big node
// absorbed by a node with fewer arcs hands over its whole set; the arcs it held keep naming
// it as their end, and ends() follows the absorbed node's `forward` to the live one.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

#include "arc_measures.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/internal/core/indices.hpp"
#include "terrain/internal/core/ranked_bits.hpp"
#include "terrain/reeb/simplify.hpp"

namespace terrain::reeb::internal {

using detail::i32;
using detail::idx;
using detail::kNone;

// Passes that gather from or scatter to random places start fetching them this many steps
// ahead.
inline constexpr std::size_t kAhead = 16;

// Nodes with at least this many arcs become big (see above): below it a node's arcs are
// scanned, above it they are looked up.
inline constexpr i32 kBigDegree = 48;

// The working graph's copy takes this many nodes, then arcs, at a time: each wave on every
// thread, then its areas summed and its arcs joined to their ends in order.
inline constexpr std::size_t kCopyWave = std::size_t{1} << 20;

class WorkingGraph {
  public:
    // Throws terrain::Error when an arc's list holds an arc end or a node of another list.
    // Nodes reaching big_degree arcs become big (kBigDegree; tests lower it to exercise big
    // nodes on small graphs and raise it to turn them off). The copy reports its progress
    // (0 to 1), as the output does: each is a pass over every node, vertex and arc. With
    // `owned` (g itself, handed over: simplify(ReebGraph&&)) the copy frees g's arrays as it
    // reads them for the last time (its values, kinds, vertex nodes and arcs), so that they
    // are not held beside the working graph at the peak of the simplification's memory; the
    // vertex lists and links stay for write_result. `memory` (simplify(ReebGraph&&)) enters
    // Stage::simplify_nodes before the nodes' areas are summed and Stage::simplify_arcs after
    // (the mesh's areas are read no more), and with `owned` stashes the new numbers of the
    // nodes and owned's vertex nodes (when write_result makes the vertex lists again from
    // them) until write_result, which enters Stage::simplify_output.
    // The copy goes `wave` nodes, then `wave` arcs, at a time (tests make it small).
    WorkingGraph(const TriangleMesh& mesh, const ReebGraph& g, i32 big_degree = kBigDegree,
                 const ProgressFn& progress = {}, ReebGraph* owned = nullptr,
                 Residency* memory = nullptr, std::size_t wave = kCopyWave);

    // The simplified graph and the rewritten field (simplify_output.cpp). The working graph is
    // freed as it goes: nothing else may be asked of it after.
    // `rewrite_field`: whether result.field is made.
    void write_result(SimplifyResult& result, bool rewrite_field, const ProgressFn& progress = {});
    // The input graph is handed over (simplify(ReebGraph&&)): write_result frees it as it
    // reads it for the last time, and leaves it empty.
    void own_input(ReebGraph& g) { owned_ = &g; }
    // The bytes it holds now: records, arc runs (freed ones included), list sets.
    std::size_t working_bytes() const;

  protected:
    // A critical node (one of the first critical_count_): its fields and its `size` arcs, the
    // newest last, with room for kInline << shift (see arc_run()). 32 bytes (asserted), two to
    // a cache line and never across one: about half the vertices of a noisy grid are critical,
    // so every byte of this record counts at the simplification's peak (an earlier record, with
    // 4 arcs inline and every field a word of its own, was larger). Most nodes have 1 to 3
    // arcs (an extremum 1, a saddle 3). Its three slots are, by its state:
    //   - a node with arcs, shift == 0 and not big: its arcs;
    //   - a node with a run in arena_ (shift > 0) or big (kBig): slot[0] is the run's offset
    //     or its BigNode;
    //   - a node absorbed or in an arc's list (kForwarded, it has no arcs then): slot[0] is
    //     its forward (see RegularNode), slot[1] and slot[2] its neighbours in the list.
    static constexpr i32 kInline = 3;
    // Arcs a node may hold (the bits of `size`): more throws terrain::Error.
    static constexpr i32 kMaxDegree = (1 << 26) - 1;
    struct alignas(32) CriticalNode {
        double area = 0;  // its vertices' and its absorbed nodes' area
        float value = 0;
        std::uint32_t size : 26 = 0;  // its arcs
        std::uint32_t shift : 6 = 0;  // room for kInline << shift arcs
        std::uint32_t down : 26 = 0;  // its arcs whose upper end it is
        std::uint32_t flags : 6 = 0;  // kCritical, kModified, kBig, kPending, kDirty, kForwarded
        mutable std::array<i32, kInline> slot{};  // (live() shortens forward paths)
    };
    static_assert(sizeof(CriticalNode) == 32);
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
    // kForwarded: its forward is set (slot[0]): it was absorbed, or it is in an arc's list.
    static constexpr std::uint8_t kForwarded = 32;
    // kBig: its arcs are in big_[slot[0]]; kPending: it has reached big_degree_ arcs and is
    // made big at the next safe point (Simplifier::promote_pending); kDirty: it waits in
    // Simplifier's list of big nodes whose candidate needs a new look.
    static constexpr std::uint8_t kBig = 4, kPending = 8, kDirty = 16;

    // The arcs of a big node. Side 0 holds the arcs below it (it is their upper end), keyed
    // by minus a value, side 1 the arcs above, keyed by the value: either way the nearest
    // come first. `far` keys by the far end's value, `near` by the value next to the node
    // along the arc (the list's nearest regular node, else the far end), `ext` holds the arcs
    // of `far` whose far end is an extremum. Keys are refreshed (refresh()) wherever an arc's
    // list, ends or ends' values change.
    struct BigNode {
        using Set = std::set<std::pair<float, i32>>;
        struct Keys {
            float far = 0, near = 0;
            std::uint8_t side = 0;
            bool ext = false;
            bool operator==(const Keys&) const = default;
        };
        std::array<Set, 2> far, near, ext;
        std::unordered_map<i32, Keys> keys;
        std::set<i32> bb;          // arcs here whose other end was big too (may hold stale ones)
        std::vector<i32> waiting;  // arcs here set waiting (may hold stale ones)
        std::vector<i32> changed;  // arcs here changed since its candidate was last chosen
        i32 rep = kNone;           // its candidate in the queue (Simplifier)
        bool full = false;         // everything changed: its candidate is looked for anew
    };
    // Any node's fields (a critical node's list neighbours are used once it is regular).
    double& area(i32 n) {
        return n < critical_count_ ? critical_[idx(n)].area
                                   : regular_[idx(n - critical_count_)].area;
    }
    float value(i32 n) const {
        return n < critical_count_ ? critical_[idx(n)].value
                                   : regular_[idx(n - critical_count_)].value;
    }
    static i32 forward_of(const CriticalNode& c) {
        return (c.flags & kForwarded) ? c.slot[0] : kNone;
    }
    i32 forward(i32 n) const {
        return n < critical_count_ ? forward_of(critical_[idx(n)])
                                   : regular_[idx(n - critical_count_)].forward;
    }
    // (A critical node's slots hold its arcs no more: it has none once absorbed or listed.)
    void set_forward(i32 n, i32 f) {
        if (n < critical_count_) {
            CriticalNode& c = critical_[idx(n)];
            c.slot[0] = f;
            c.flags |= kForwarded;
        } else {
            regular_[idx(n - critical_count_)].forward = f;
        }
    }
    i32& prev(i32 n) {
        return n < critical_count_ ? critical_[idx(n)].slot[1]
                                   : regular_[idx(n - critical_count_)].prev;
    }
    i32& next(i32 n) {
        return n < critical_count_ ? critical_[idx(n)].slot[2]
                                   : regular_[idx(n - critical_count_)].next;
    }

    // The live node that node n's vertices went to (n itself while it lives): absorbed
    // critical nodes name the node that took them in `forward`.
    i32 live(i32 n) const {
        // (each step halves the path: a node handed over many times is found in a few steps)
        for (;;) {
            const CriticalNode& c = critical_[idx(n)];
            const i32 f = forward_of(c);
            if (f < 0) return n;
            const i32 ff = forward_of(critical_[idx(f)]);
            if (ff >= 0) c.slot[0] = ff;
            n = f;
        }
    }
    // Arc b's {lower, upper} ends, live: ends naming an absorbed node (arcs handed over in a
    // big node's set, see above) are set to the node that took it.
    const std::array<i32, 2>& ends(i32 b) const {
        auto& e = arcs_[idx(b)].end;
        for (i32& n : e)
            if (forward_of(critical_[idx(n)]) >= 0) n = live(n);
        return e;
    }
    i32 other_end(i32 b, i32 n) const {
        const auto& e = ends(b);
        return e[0] == n ? e[1] : e[0];
    }
    bool big(i32 n) const { return (critical_[idx(n)].flags & kBig) != 0; }
    BigNode& big_of(i32 n) { return big_[idx(critical_[idx(n)].slot[0])]; }
    const BigNode& big_of(i32 n) const { return big_[idx(critical_[idx(n)].slot[0])]; }
    // Whether arc b is queued through a big end's candidate rather than on its own.
    bool managed(i32 b) const {
        const auto& e = ends(b);
        return big(e[0]) || big(e[1]);
    }

    // A critical node's arcs, the newest last: in its record while they fit, else in the arena.
    i32* arc_run(CriticalNode& c) {
        return c.shift == 0 ? c.slot.data() : arena_.data() + c.slot[0];
    }
    const i32* arc_run(const CriticalNode& c) const {
        return c.shift == 0 ? c.slot.data() : arena_.data() + c.slot[0];
    }
    // The arcs at a critical node, newest first (a big node's: below it, then above it,
    // nearest first).
    template <class F>
    void for_each_arc(i32 n, F&& f) const {
        if (big(n)) {
            for (const auto& side : big_of(n).far)
                for (const auto& entry : side) f(entry.second);
            return;
        }
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
        ++moves_;
        CriticalNode& c = critical_[idx(n)];
        if (c.size == kMaxDegree)
            throw Error("simplify", "a node has more arcs than the working graph can hold (2^26)");
        if (c.flags & kBig) {
            big_insert(n, a);
            ++c.size;
            return;
        }
        if (c.size + 1 >= big_degree_ && !(c.flags & kPending)) {
            c.flags |= kPending;
            pending_big_.push_back(n);
        }
        if (c.size == kInline << c.shift) {
            const std::uint8_t shift = static_cast<std::uint8_t>(c.shift + 1);
            const i32 offset = take_run(shift);
            std::copy_n(arc_run(c), c.size, arena_.data() + offset);
            release_run(c);
            c.slot[0] = offset;
            c.shift = shift;
        }
        arc_run(c)[c.size++] = a;
    }
    // Arc a leaves node n (the newest of its entries there, for an arc with both ends at n).
    void unlink(i32 a, i32 n) {
        CriticalNode& c = critical_[idx(n)];
        if (c.flags & kBig) {
            big_erase(n, a);
            --c.size;
            return;
        }
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
        if (c.flags & kBig) {
            release_big(c);
            return;
        }
        if (c.shift == 0) return;
        free_runs_[c.shift].push_back(c.slot[0]);
        c.shift = 0;
    }
    // A run with room for kInline << shift arcs: a freed one, or a new one at the arena's end.
    i32 take_run(std::uint8_t shift);

    // What the output reads of the working graph, taken out: the nodes that remain (a bit by
    // their index here, with their values by rank) and the arcs that live, with their lists (a
    // few thousand nodes on a grid simplified at a single scale; with the landform defaults'
    // low area threshold, half the vertices). The working graph then goes, before the new
    // numbers come back (parked through the cancellations) and the arrays of every node and
    // vertex are made. Taking them out is the peak of the simplification's memory, beside the
    // whole working graph: a remaining node costs its value (4 bytes) and, among the first
    // critical_count_ indices only, its kind and links (4 bytes).
    struct RemainingCritical {
        NodeKind kind = NodeKind::regular;
        std::uint8_t lower = 1, upper = 1;  // link counts, for a critical node changed
        bool changed = false;
    };
    static_assert(sizeof(RemainingCritical) == 4);
    struct Remains {
        detail::RankedBits nodes;                   // the indices here that remain
        std::vector<float> values;                  // their values, by rank
        std::vector<RemainingCritical> critical;    // those below critical_count_, by rank
        std::vector<std::array<i32, 2>> live_ends;  // the arcs that live, in order
        std::vector<i32> live_offsets, live_nodes;
    };
    // write_result's passes (simplify_output.cpp). final_codes: code[i], for an absorbed node
    // the critical node that finally took it, for a remaining node kNone, the critical nodes'
    // (the regular nodes' are written over their forwards; 0 to 0.2 of the progress);
    // take_remains (to 0.3); renumber: the remaining nodes numbered in the order of the old
    // ones, node_map_ each old node's new node, `gone` the absorbed ones, returning {old
    // node, internal index} by new id (to 0.4); write_nodes_and_arcs: the output's nodes and
    // arcs; vertex_counts: each new node's vertex count; remake_vertex_lists: the input's
    // vertex lists again from its vertices' nodes, when they are to be (to 0.5);
    // write_vertices: the vertices grouped by new node, each one's node, absorbed flag and
    // value (to 1).
    std::vector<i32> final_codes(const ProgressFn& progress);
    Remains take_remains(const std::vector<i32>& code, const ProgressFn& progress);
    std::vector<std::array<i32, 2>> renumber(std::vector<i32>& code,
                                             std::vector<std::uint8_t>& gone,
                                             const ProgressFn& progress);
    void write_nodes_and_arcs(ReebGraph& out, const std::vector<std::array<i32, 2>>& kept,
                              const Remains& remains, const std::vector<i32>& code);
    std::vector<i32> vertex_counts(std::size_t count);
    void remake_vertex_lists(const ProgressFn& progress);
    void write_vertices(SimplifyResult& result, bool rewrite_field, std::vector<i32>& size,
                        const std::vector<std::uint8_t>& gone, const ProgressFn& progress);

    // The copy's passes (working_graph.cpp). number_listed_nodes: node_map_ marks the arc ends
    // and numbers the lists' regular nodes by their position in the lists (0 to 0.1 of the
    // progress); copy_nodes: the nodes' records and areas, a wave at a time (0.1 to 0.6),
    // returning whether every node's vertex list is ascending; release_copied_nodes: what of
    // `owned` write_result will not read; copy_arcs: the arcs' records and lists, each arc
    // joined to its ends (0.7 to 1). critical_nodes: the arc ends and the lists' critical
    // nodes, a bit each, a critical node's new number its rank among them.
    void number_listed_nodes(const ReebGraph& g, const ProgressFn& progress);
    bool copy_nodes(const TriangleMesh& mesh, const ReebGraph& g,
                    const detail::RankedBits& critical_nodes, ReebGraph* owned, std::size_t wave,
                    const ProgressFn& progress);
    void release_copied_nodes(ReebGraph& owned, bool sorted);
    void copy_arcs(const ReebGraph& g, const detail::RankedBits& critical_nodes, ReebGraph* owned,
                   std::size_t wave, const ProgressFn& progress);

    // Big nodes (working_graph.cpp). make_big moves node n's run into a new BigNode;
    // release_big gives a node's BigNode back (emptied) once the node is gone.
    void make_big(i32 n);
    void release_big(CriticalNode& c);
    // Arc b's keys at big node n, as they are now.
    BigNode::Keys keys_of(i32 b, i32 n) const;
    void big_insert(i32 n, i32 b);
    void big_erase(i32 n, i32 b);
    // Arc b's keys at its big ends made current; returns whether they changed at n.
    bool refresh(i32 n, i32 b);
    void refresh_ends(i32 b) {
        const auto e = ends(b);
        if (big(e[0])) refresh(e[0], b);
        if (e[1] != e[0] && big(e[1])) refresh(e[1], b);
    }

    // Arcs below and above a critical node: its arcs ending there as the upper / lower end
    // (`down` is updated wherever an arc end moves or an arc turns around).
    i32 degree(i32 n) const { return critical_[idx(n)].size; }
    i32 down(i32 n) const { return critical_[idx(n)].down; }
    i32 up(i32 n) const { return critical_[idx(n)].size - critical_[idx(n)].down; }
    bool extremum(i32 n) const { return down(n) == 0 || up(n) == 0; }
    // The measures of arc a (arc_measures.hpp).
    float persistence(i32 a) const {
        const auto& e = ends(a);
        return internal::persistence(value(e[0]), value(e[1]));
    }
    double area_ratio(i32 a) const {
        const Arc& arc = arcs_[idx(a)];
        const auto [lo, hi] = ends(a);
        const auto add_list_area = [&](double sum) { return sum + arc.area; };
        return internal::area_ratio(critical_[idx(lo)].area, degree(lo), critical_[idx(hi)].area,
                                    degree(hi), add_list_area, total_area_);
    }
    // Whether another arc joins the same two nodes as arc a (a loop of the graph).
    bool has_parallel_arc(i32 a) const {
        const auto end = ends(a);
        const i32 n = degree(end[0]) <= degree(end[1]) ? end[0] : end[1];
        if (degree(n) == 1) return false;  // a is its only arc
        bool found = false;
        for_each_arc(n, [&](i32 b) {
            if (b == a || found) return;
            const auto& e = ends(b);
            found |= (e[0] == end[0] && e[1] == end[1]) || (e[0] == end[1] && e[1] == end[0]);
        });
        return found;
    }
    // Node n's vertices (and everything already forwarded to it) join the critical node keep.
    void absorb(i32 n, i32 keep) {
        set_forward(n, keep);
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
    // g_'s node and vertex counts (a graph handed over may have given up the arrays they
    // come from once copied).
    std::size_t input_nodes_ = 0, input_vertices_ = 0;
    // Each node of g_: its number here (then, in write_result, its node in the result).
    std::vector<i32> node_map_;
    i32 critical_count_ = 0;  // critical nodes: 0 .. critical_count_ - 1
    std::vector<CriticalNode> critical_;
    std::vector<RegularNode> regular_;  // node critical_count_ + i is regular_[i]
    std::vector<i32> arena_;
    std::array<std::vector<i32>, 32> free_runs_;  // freed runs by shift
    std::size_t arena_peak_ = 0;                  // the arena's largest size, entries
    double total_area_ = 0;
    std::vector<i32> set_parent_;    // of each set, kNone for a root (an arc's current set)
    std::vector<i32> set_fate_;      // of each root set: the node that absorbed it, or kNone
    mutable std::vector<Arc> arcs_;  // (ends() sets live ends as it reads them)
    i32 big_degree_ = kBigDegree;
    std::vector<BigNode> big_;      // the big nodes' arcs (a node's BigNode at its offset)
    std::vector<i32> free_big_;     // BigNodes given back, for reuse
    std::vector<i32> pending_big_;  // nodes flagged kPending
    ReebGraph* owned_ = nullptr;    // the input graph, when handed over (own_input)
    // A graph handed over whose vertex lists are all ascending (build_reeb_graph's) gives up
    // its lists (4 bytes a vertex and 4 a node) once the nodes are copied and keeps its
    // vertex_nodes (4 bytes a vertex): write_result makes the same lists again from them, once
    // the working graph is freed.
    bool lists_from_vertex_nodes_ = false;
    Residency* memory_ = nullptr;  // stashed: node_map_, owned's vertex nodes (after the copy)
    // Frees the records, runs, arcs, sets and big nodes (write_result, once the arcs are out).
    void release_working_graph();  // all but regular_ (the output reads it after)
    std::size_t moves_ = 0;        // link() calls
};

}  // namespace terrain::reeb::internal
