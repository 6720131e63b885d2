// Critical-node cancellation on a Reeb graph (docs/reeb.md). The graph is copied into a
// mutable form: nodes renumbered so that each arc's regular nodes start out side by side,
// each node's arcs in a run of an arena, regular nodes in doubly linked lists (one per arc,
// sorted by value), absorbed nodes forwarding to the node that took them. Candidates wait in
// a priority queue keyed by (persistence, arc id) with lazy deletion: each arc remembers the
// key of its live entry, entries with another key are stale and skipped, and a popped arc is
// checked again before it is cancelled.

#include "terrain/reeb/simplify.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "../core/indices.hpp"
#include "terrain/core/error.hpp"

namespace terrain::reeb {

namespace {

using detail::i32;
using detail::kNone;
using detail::z;

// The arcs at each node, each node's in a run of an arena (newest last, read newest first),
// and the number of those arcs that end there from below. A run that fills up moves to the
// arena's end with twice the room; a node that loses all its arcs keeps its run.
class Incidence {
  public:
    // Arcs a = 0, 1, ... join their ends in turn.
    void init(std::size_t nodes, const std::vector<std::array<i32, 2>>& ends) {
        node_.assign(nodes, Run{});
        for (const auto& e : ends) {
            ++node_[z(e[0])].size;
            ++node_[z(e[1])].size;
            ++node_[z(e[1])].down;
        }
        i32 offset = 0;
        for (Run& r : node_) {
            r.offset = offset;
            r.room = r.size;
            offset += r.size;
            r.size = 0;
        }
        arcs_.resize(z(offset));
        for (std::size_t a = 0; a < ends.size(); ++a)
            for (const i32 n : ends[a]) {
                Run& r = node_[z(n)];
                arcs_[z(r.offset + r.size++)] = static_cast<i32>(a);
            }
    }
    void link(i32 a, i32 n) {
        Run& r = node_[z(n)];
        if (r.size == r.room) {
            const i32 offset = static_cast<i32>(arcs_.size());
            r.room = std::max(4, 2 * r.room);
            arcs_.resize(arcs_.size() + z(r.room));
            std::copy_n(arcs_.begin() + r.offset, r.size, arcs_.begin() + offset);
            r.offset = offset;
        }
        arcs_[z(r.offset + r.size++)] = a;
    }
    // Arc a leaves node n (the newest of its entries there, for an arc with both ends at n).
    void unlink(i32 a, i32 n) {
        Run& r = node_[z(n)];
        const auto first = arcs_.begin() + r.offset, last = first + r.size;
        auto it = last - 1;
        while (*it != a) --it;
        std::copy(it + 1, last, it);
        --r.size;
    }
    // All of node n's arcs leave it.
    void clear(i32 n) { node_[z(n)].size = 0; }
    i32 degree(i32 n) const { return node_[z(n)].size; }
    i32& down(i32 n) { return node_[z(n)].down; }
    i32 down(i32 n) const { return node_[z(n)].down; }
    template <class F>
    void for_each(i32 n, F&& f) const {
        const Run& r = node_[z(n)];
        for (i32 i = r.offset + r.size - 1; i >= r.offset; --i) f(arcs_[z(i)]);
    }
    void arcs(i32 n, std::vector<i32>& out) const {
        out.clear();
        for_each(n, [&](i32 a) { out.push_back(a); });
    }

  private:
    struct Run {
        i32 offset = 0, size = 0, room = 0;
        i32 down = 0;  // arcs whose upper end is the node
    };
    std::vector<Run> node_;
    std::vector<i32> arcs_;
};

// Min-priority queue of 64-bit keys: a radix heap (keys at or above the last key popped, in
// buckets by the highest bit where they differ from it) with a binary heap beside it for the
// few keys pushed below that. Pops come in the same order as from any exact min-heap.
class KeyQueue {
  public:
    bool empty() const { return size_ == 0 && low_.empty(); }
    void push(std::uint64_t key) {
        if (key < last_) {
            low_.push_back(key);
            std::push_heap(low_.begin(), low_.end(), std::greater<>());
        } else {
            bucket_[z(std::bit_width(key ^ last_))].push_back(key);
            ++size_;
        }
    }
    std::uint64_t pop() {
        if (size_ > 0 && bucket_[0].empty()) refill();
        if (!low_.empty() && (size_ == 0 || low_.front() < last_)) {
            std::pop_heap(low_.begin(), low_.end(), std::greater<>());
            const std::uint64_t key = low_.back();
            low_.pop_back();
            return key;
        }
        bucket_[0].pop_back();
        --size_;
        return last_;
    }

  private:
    // The smallest non-empty bucket's minimum becomes last_; its keys spread over the lower
    // buckets (bucket 0 holds the keys equal to last_).
    void refill() {
        std::size_t i = 1;
        while (bucket_[i].empty()) ++i;
        std::vector<std::uint64_t>& b = bucket_[i];
        last_ = *std::min_element(b.begin(), b.end());
        for (const std::uint64_t key : b) bucket_[z(std::bit_width(key ^ last_))].push_back(key);
        b.clear();
    }

    std::array<std::vector<std::uint64_t>, 65> bucket_;
    std::size_t size_ = 0;  // keys in the buckets
    std::uint64_t last_ = 0;
    std::vector<std::uint64_t> low_;  // keys below last_, a min-heap
};

std::vector<double> node_areas(const TriangleMesh& mesh, const ReebGraph& g) {
    std::vector<double> area(g.node_count(), 0.0);
    for (std::size_t v = 0; v < g.vertex_nodes.size(); ++v)
        area[z(g.vertex_nodes[v])] += mesh.vertex_areas.empty() ? 1.0 : mesh.vertex_areas[v];
    return area;
}

// The summed area of node n's vertices, added in increasing vertex order (as a sweep over
// the vertices would add them).
double node_area(const TriangleMesh& mesh, const ReebGraph& g, std::size_t n,
                 std::vector<i32>& scratch) {
    const auto first = g.node_vertices.begin() + g.node_vertex_offsets[n];
    const auto last = g.node_vertices.begin() + g.node_vertex_offsets[n + 1];
    const i32* v = &*first;
    std::size_t count = static_cast<std::size_t>(last - first);
    if (!std::is_sorted(first, last)) {
        scratch.assign(first, last);
        std::sort(scratch.begin(), scratch.end());
        v = scratch.data();
    }
    double s = 0;
    for (std::size_t i = 0; i < count; ++i)
        s += mesh.vertex_areas.empty() ? 1.0 : mesh.vertex_areas[z(v[i])];
    return s;
}

// Nodes are renumbered for locality: first the nodes that are in no arc's list (the critical
// ones, the only possible arc ends), in their order, then the listed regular nodes in the
// order of arc_nodes, so that each arc's list starts out contiguous in memory.
class Simplifier {
  public:
    Simplifier(const TriangleMesh& mesh, const ReebGraph& g, const SimplifyOptions& options)
        : g_(g), options_(options) {
        const std::size_t nn = g.node_count(), na = g.arc_count(), nl = g.arc_nodes.size();
        // at_[n]: arc ends marked, the other regular nodes of the lists by their position in
        // arc_nodes (placed_ says which positions hold their node); then the new numbers.
        constexpr i32 kEnd = -2;
        at_.assign(nn, kNone);
        for (const auto& e : g.arcs) at_[z(e[0])] = at_[z(e[1])] = kEnd;
        std::vector<char> placed(nl, 0);
        for (std::size_t p = 0; p < nl; ++p) {
            const i32 r = g.arc_nodes[p];
            if (at_[z(r)] != kNone || g.node_kinds[z(r)] != NodeKind::regular) continue;
            at_[z(r)] = static_cast<i32>(p);
            placed[p] = 1;
        }
        i32 first = 0;
        for (const i32 i : at_) first += i < 0;
        nodes_.resize(z(first) + nl);
        critical_.resize(z(first));
        modified_.assign(z(first), 0);
        total_area_ = 0;
        std::vector<i32> scratch;
        i32 k = 0;
        for (std::size_t n = 0; n < nn; ++n) {
            const double area = node_area(mesh, g, n, scratch);
            total_area_ += area;
            const i32 i = at_[n] < 0 ? k++ : first + at_[n];
            at_[n] = i;
            nodes_[z(i)].value = g.node_values[n];
            nodes_[z(i)].area = area;
            if (i < first) critical_[z(i)] = g.node_kinds[n] != NodeKind::regular;
        }
        if (total_area_ <= 0) total_area_ = 1;
        arcs_.resize(na);
        queued_.assign(na, 0);
        std::vector<std::array<i32, 2>> ends(na);
        for (std::size_t a = 0; a < na; ++a)
            ends[a] = arcs_[a].end = {at_[z(g.arcs[a][0])], at_[z(g.arcs[a][1])]};
        inc_.init(z(first), ends);
        for (std::size_t a = 0; a < na; ++a) {
            Arc& arc = arcs_[a];
            for (i32 p = g.arc_offsets[a]; p < g.arc_offsets[a + 1]; ++p) {
                const i32 r = placed[z(p)] ? first + p : at_[z(g.arc_nodes[z(p)])];
                if (arc.tail == kNone)
                    arc.head = r;
                else
                    nodes_[z(arc.tail)].next = r, nodes_[z(r)].prev = arc.tail;
                arc.tail = r;
                arc.area += nodes_[z(r)].area;
            }
        }
    }

    void run(const ProgressFn& progress, SimplifyResult& result) {
        for (std::size_t a = 0; a < arcs_.size(); ++a) consider(static_cast<i32>(a));
        const std::size_t initial = pushed_;
        std::size_t done = 0;
        while (!heap_.empty()) {
            const std::uint64_t key = heap_.pop();
            const i32 a = static_cast<i32>(key & 0xffffffffu);
            if (queued_[z(a)] != key) continue;
            queued_[z(a)] = 0;
            if (!candidate(a)) continue;
            cancel(a, result);
            if ((++done & 0xfff) == 0 && initial > 0)
                report_progress(progress, std::min(0.9, 0.9 * done / static_cast<double>(initial)),
                                "simplify");
        }
        output(result);
        report_progress(progress, 1.0, "simplify");
    }

  private:
    struct Node {
        double area = 0;  // its vertices' and its absorbed nodes' area
        float value = 0;
        i32 forward = kNone;             // the node that absorbed it
        i32 prev = kNone, next = kNone;  // its neighbours in its arc's list
    };
    struct Arc {
        std::array<i32, 2> end{kNone, kNone};  // {lower, upper}
        i32 head = kNone, tail = kNone;        // regular nodes, lower to upper
        double area = 0;                       // area of the regular nodes' vertices
        bool alive = true;
    };
    // Heap key: the persistence's order-preserving bits, then the arc id (ties by id).
    static std::uint64_t key_of(float persistence, i32 a) {
        return (std::uint64_t{std::bit_cast<std::uint32_t>(persistence)} << 32) |
               static_cast<std::uint32_t>(a);
    }

    // Arcs below and above a node: its arcs ending there as the upper / lower end (the
    // incidence updates its count below wherever an arc end moves or an arc turns around).
    i32 down(i32 n) const { return inc_.down(n); }
    i32 up(i32 n) const { return inc_.degree(n) - inc_.down(n); }
    bool extremum(i32 n) const { return down(n) == 0 || up(n) == 0; }
    float persistence(i32 a) const {
        const Arc& arc = arcs_[z(a)];
        return std::fabs(nodes_[z(arc.end[1])].value - nodes_[z(arc.end[0])].value);
    }
    double area_ratio(i32 a) const {
        const Arc& arc = arcs_[z(a)];
        double s = arc.area;
        for (const i32 n : arc.end) s += nodes_[z(n)].area / static_cast<double>(inc_.degree(n));
        return s / total_area_;
    }
    bool multi(i32 a) const {
        const Arc& arc = arcs_[z(a)];
        const i32 n = inc_.degree(arc.end[0]) <= inc_.degree(arc.end[1]) ? arc.end[0] : arc.end[1];
        bool found = false;
        inc_.for_each(n, [&](i32 b) {
            if (b == a) return;
            const auto& e = arcs_[z(b)].end;
            found |= (e[0] == arc.end[0] && e[1] == arc.end[1]) ||
                     (e[0] == arc.end[1] && e[1] == arc.end[0]);
        });
        return found;
    }
    bool candidate(i32 a) const {
        const Arc& arc = arcs_[z(a)];
        if (!arc.alive) return false;
        if (!extremum(arc.end[0]) && !extremum(arc.end[1])) return false;
        if (multi(a)) return false;
        return persistence(a) < options_.persistence || area_ratio(a) < options_.area_ratio / 100.0;
    }
    // (Re)queues arc a if it is a candidate; a queued entry with the same key is kept.
    void consider(i32 a) {
        std::uint64_t& queued = queued_[z(a)];
        if (!candidate(a)) {
            queued = 0;
            return;
        }
        const std::uint64_t key = key_of(persistence(a), a);
        if (queued == key) return;
        queued = key;
        heap_.push(key);
        ++pushed_;
    }

    // Node n's vertices (and everything already forwarded to it) join `keep`.
    void absorb(i32 n, i32 keep) {
        nodes_[z(n)].forward = keep;
        nodes_[z(keep)].area += nodes_[z(n)].area;
    }
    void absorb_list(Arc& arc, i32 keep) {
        for (i32 r = arc.head; r != kNone; r = nodes_[z(r)].next) absorb(r, keep);
        arc.head = arc.tail = kNone;
        arc.area = 0;
    }

    // Arc b now ends at keep (whose value may have changed): regular nodes outside the new
    // value range join keep, and the ends swap if the other end is now on the wrong side.
    void fit_arc(i32 b, i32 keep) {
        Arc& arc = arcs_[z(b)];
        const float fk = nodes_[z(keep)].value;
        if (arc.end[1] == keep) {
            while (arc.tail != kNone && nodes_[z(arc.tail)].value > fk) {
                const i32 r = arc.tail;
                arc.tail = nodes_[z(r)].prev;
                if (arc.tail == kNone)
                    arc.head = kNone;
                else
                    nodes_[z(arc.tail)].next = kNone;
                arc.area -= nodes_[z(r)].area;
                absorb(r, keep);
            }
            if (nodes_[z(arc.end[0])].value > fk) {
                absorb_list(arc, keep);
                ++inc_.down(arc.end[0]);
                --inc_.down(keep);
                std::swap(arc.end[0], arc.end[1]);
            }
        } else {
            while (arc.head != kNone && nodes_[z(arc.head)].value < fk) {
                const i32 r = arc.head;
                arc.head = nodes_[z(r)].next;
                if (arc.head == kNone)
                    arc.tail = kNone;
                else
                    nodes_[z(arc.head)].prev = kNone;
                arc.area -= nodes_[z(r)].area;
                absorb(r, keep);
            }
            if (nodes_[z(arc.end[1])].value < fk) {
                absorb_list(arc, keep);
                --inc_.down(arc.end[1]);
                ++inc_.down(keep);
                std::swap(arc.end[0], arc.end[1]);
            }
        }
        if (arc.head == kNone) arc.area = 0;
    }

    void cancel(i32 a, SimplifyResult& result) {
        Arc& arc = arcs_[z(a)];
        const i32 lo = arc.end[0], hi = arc.end[1];
        const bool lo_ext = down(lo) == 0, hi_ext = up(hi) == 0;
        i32 keep, gone;
        const i32 keep0 = lo_ext && hi_ext ? lo : (lo_ext ? hi : lo);
        const double share_before = nodes_[z(keep0)].area / static_cast<double>(inc_.degree(keep0));
        const bool ext_before = extremum(keep0);
        if (lo_ext && hi_ext) {
            keep = lo;
            gone = hi;
            nodes_[z(keep)].value = 0.5f * (nodes_[z(lo)].value + nodes_[z(hi)].value);
            ++result.extremum_extremum;
        } else {
            keep = lo_ext ? hi : lo;
            gone = lo_ext ? lo : hi;
            ++result.saddle_extremum;
        }
        modified_[z(keep)] = 1;
        arc.alive = false;
        inc_.unlink(a, lo);
        inc_.unlink(a, hi);
        --inc_.down(hi);
        absorb_list(arc, keep);
        absorb(gone, keep);
        std::vector<i32>& touched = touched_;
        inc_.arcs(gone, touched);
        inc_.clear(gone);
        for (const i32 b : touched) {
            Arc& other = arcs_[z(b)];
            inc_.link(b, keep);
            for (auto& e : other.end)
                if (e == gone) e = keep;
            inc_.down(keep) += other.end[1] == keep;
        }
        inc_.down(gone) = 0;
        if (lo_ext && hi_ext) {
            inc_.arcs(keep, all_);
            for (const i32 b : all_) fit_arc(b, keep);
        } else {
            for (const i32 b : touched) fit_arc(b, keep);
        }
        // keep's other arcs need a new look only if they may have become candidates: its
        // value moved, it became an extremum, or its area share per arc went down. Arcs that
        // stopped being candidates are dropped when they reach the top of the heap.
        const double share_after =
            inc_.degree(keep) == 0 ? 0.0
                                   : nodes_[z(keep)].area / static_cast<double>(inc_.degree(keep));
        if ((lo_ext && hi_ext) || extremum(keep) != ext_before || share_after < share_before)
            inc_.arcs(keep, touched);

        // A node left with one arc below and one above becomes regular: its arcs merge.
        if (inc_.degree(keep) == 2 && down(keep) == 1 && up(keep) == 1) {
            inc_.arcs(keep, all_);
            i32 lower = all_[0], upper = all_[1];
            if (arcs_[z(lower)].end[1] != keep) std::swap(lower, upper);
            Arc& L = arcs_[z(lower)];
            Arc& U = arcs_[z(upper)];
            if (L.end[0] != U.end[1]) {
                Node& k = nodes_[z(keep)];
                k.prev = L.tail;
                k.next = U.head;
                if (L.tail == kNone)
                    L.head = keep;
                else
                    nodes_[z(L.tail)].next = keep;
                if (U.head != kNone) nodes_[z(U.head)].prev = keep;
                L.tail = U.tail == kNone ? keep : U.tail;
                L.area += k.area + U.area;
                const i32 q = U.end[1];
                L.end[1] = q;
                U.alive = false;
                inc_.unlink(upper, q);
                inc_.unlink(upper, keep);
                inc_.unlink(lower, keep);
                inc_.link(lower, q);
                inc_.down(keep) = 0;
                critical_[z(keep)] = false;
                touched.assign(1, lower);
                inc_.for_each(L.end[0], [&](i32 b) {
                    if (b != lower && arcs_[z(b)].end == L.end) touched.push_back(b);
                });
            }
        }
        for (const i32 b : touched) consider(b);
    }

    void output(SimplifyResult& result) {
        const std::size_t nn = g_.node_count();
        // Forwarding chains end at the nodes that remain; shortened to one step each.
        for (Node& node : nodes_) {
            i32 r = node.forward;
            if (r == kNone) continue;
            while (nodes_[z(r)].forward != kNone) r = nodes_[z(r)].forward;
            for (i32 n = node.forward; n != r;) {
                const i32 nx = nodes_[z(n)].forward;
                nodes_[z(n)].forward = r;
                n = nx;
            }
            node.forward = r;
        }
        // New ids, in the order of the old ones, by internal index.
        std::vector<i32> new_id(nodes_.size(), kNone);
        i32 count = 0;
        for (std::size_t n = 0; n < nn; ++n)
            if (nodes_[z(at_[n])].forward == kNone) new_id[z(at_[n])] = count++;
        ReebGraph& out = result.graph;
        out.node_values.resize(z(count));
        out.node_kinds.assign(z(count), NodeKind::regular);
        out.node_lower_links.assign(z(count), 1);
        out.node_upper_links.assign(z(count), 1);
        out.node_arcs.assign(z(count), kNone);
        const i32 first = static_cast<i32>(critical_.size());
        for (std::size_t n = 0; n < nn; ++n) {
            const i32 i = at_[n];
            const i32 nid = new_id[z(i)];
            if (nid == kNone) continue;
            out.node_values[z(nid)] = nodes_[z(i)].value;
            if (i >= first || !critical_[z(i)]) continue;
            const i32 d = down(i), u = up(i);
            out.node_kinds[z(nid)] = d == 0   ? NodeKind::minimum
                                     : u == 0 ? NodeKind::maximum
                                              : NodeKind::saddle;
            const bool unchanged = !modified_[z(i)];
            out.node_lower_links[z(nid)] =
                unchanged ? g_.node_lower_links[n] : static_cast<std::uint8_t>(std::min(d, 255));
            out.node_upper_links[z(nid)] =
                unchanged ? g_.node_upper_links[n] : static_cast<std::uint8_t>(std::min(u, 255));
        }
        // Vertices: grouped by new node, in the order of their old nodes.
        std::vector<i32> size(z(count) + 1, 0);
        std::vector<i32> old_root(nn);
        for (std::size_t n = 0; n < nn; ++n) {
            const i32 i = at_[n], f = nodes_[z(i)].forward;
            old_root[n] = new_id[z(f == kNone ? i : f)];
            size[z(old_root[n]) + 1] += g_.node_vertex_offsets[n + 1] - g_.node_vertex_offsets[n];
        }
        for (std::size_t i = 1; i < size.size(); ++i) size[i] += size[i - 1];
        out.node_vertex_offsets = size;
        out.node_vertices.resize(g_.node_vertices.size());
        out.vertex_nodes.resize(g_.vertex_nodes.size());
        result.field.resize(g_.vertex_nodes.size());
        for (std::size_t n = 0; n < nn; ++n) {
            const i32 nid = old_root[n];
            const float value = out.node_values[z(nid)];
            for (i32 i = g_.node_vertex_offsets[n]; i < g_.node_vertex_offsets[n + 1]; ++i) {
                const i32 v = g_.node_vertices[z(i)];
                out.node_vertices[z(size[z(nid)]++)] = v;
                out.vertex_nodes[z(v)] = nid;
                result.field[z(v)] = value;
            }
        }
        out.arc_offsets.assign(1, 0);
        for (const Arc& arc : arcs_) {
            if (!arc.alive) continue;
            const i32 id = static_cast<i32>(out.arcs.size());
            out.arcs.push_back({new_id[z(arc.end[0])], new_id[z(arc.end[1])]});
            for (i32 r = arc.head; r != kNone; r = nodes_[z(r)].next) {
                out.arc_nodes.push_back(new_id[z(r)]);
                out.node_arcs[z(new_id[z(r)])] = id;
            }
            out.arc_offsets.push_back(static_cast<i32>(out.arc_nodes.size()));
        }
    }

    const ReebGraph& g_;
    SimplifyOptions options_;
    std::vector<i32> at_;  // the internal index of each node
    std::vector<Node> nodes_;
    std::vector<char> critical_, modified_;  // of the first nodes (the others are regular)
    double total_area_ = 0;
    Incidence inc_;
    std::vector<i32> touched_, all_;
    std::vector<Arc> arcs_;
    std::vector<std::uint64_t> queued_;  // key of each arc's live heap entry, 0 when none
    KeyQueue heap_;
    std::size_t pushed_ = 0;
};

}  // namespace

ArcMetrics arc_metrics(const TriangleMesh& mesh, const ReebGraph& g) {
    const auto area = node_areas(mesh, g);
    double total = 0;
    for (const double a : area) total += a;
    if (total <= 0) total = 1;
    const NodeArcs inc = node_arcs(g);
    ArcMetrics m;
    m.persistence.resize(g.arc_count());
    m.area_ratio.resize(g.arc_count());
    for (std::size_t a = 0; a < g.arc_count(); ++a) {
        const auto [lo, hi] = g.arcs[a];
        m.persistence[a] = std::fabs(g.node_values[z(hi)] - g.node_values[z(lo)]);
        double s = area[z(lo)] / static_cast<double>(inc.degree(lo)) +
                   area[z(hi)] / static_cast<double>(inc.degree(hi));
        for (i32 i = g.arc_offsets[a]; i < g.arc_offsets[a + 1]; ++i)
            s += area[z(g.arc_nodes[z(i)])];
        m.area_ratio[a] = s / total;
    }
    return m;
}

void check_simplify_options(const SimplifyOptions& options) {
    if (!std::isfinite(options.persistence) || options.persistence < 0)
        throw Error("simplify", "the persistence threshold must be a number >= 0");
    if (!std::isfinite(options.area_ratio) || options.area_ratio < 0 || options.area_ratio > 100)
        throw Error("simplify", "the area ratio is a percentage: it must be between 0 and 100");
}

SimplifyResult simplify(const TriangleMesh& mesh, const ReebGraph& graph,
                        const SimplifyOptions& options, const ProgressFn& progress) {
    check_simplify_options(options);
    if (graph.vertex_nodes.size() != mesh.vertex_count())
        throw Error("simplify", "the graph was not built on this mesh");
    SimplifyResult result;
    Simplifier(mesh, graph, options).run(progress, result);
    return result;
}

}  // namespace terrain::reeb
