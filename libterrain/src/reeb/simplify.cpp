// Critical-node cancellation on a Reeb graph (docs/reeb.md). The graph is copied into a
// mutable form: each node's arcs in a linked list of arc ends, regular nodes in doubly linked
// lists (one per arc, sorted by value), absorbed nodes forwarding to the node that took them.
// Candidates wait in a min-heap keyed by (persistence, arc id) with lazy deletion: each arc
// remembers the key of its live entry, entries with another key are stale and skipped, and a
// popped arc is checked again before it is cancelled.

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

// The arcs at each node as doubly linked lists of arc ends (slot 2a and 2a+1 of arc a), so
// that moving an arc end from one node to another allocates nothing.
class Incidence {
  public:
    void init(std::size_t nodes, std::size_t arcs) {
        head_.assign(nodes, kNone);
        degree_.assign(nodes, 0);
        next_.assign(2 * arcs, kNone);
        prev_.assign(2 * arcs, kNone);
        owner_.assign(2 * arcs, kNone);
    }
    void link(i32 slot, i32 node) {
        owner_[z(slot)] = node;
        prev_[z(slot)] = kNone;
        next_[z(slot)] = head_[z(node)];
        if (head_[z(node)] != kNone) prev_[z(head_[z(node)])] = slot;
        head_[z(node)] = slot;
        ++degree_[z(node)];
    }
    void unlink(i32 slot) {
        const i32 node = owner_[z(slot)], p = prev_[z(slot)], n = next_[z(slot)];
        if (p != kNone)
            next_[z(p)] = n;
        else
            head_[z(node)] = n;
        if (n != kNone) prev_[z(n)] = p;
        --degree_[z(node)];
        owner_[z(slot)] = kNone;
    }
    void move(i32 slot, i32 node) {
        unlink(slot);
        link(slot, node);
    }
    // The slot of arc a's end at node n.
    i32 slot(i32 a, i32 n) const { return owner_[z(2 * a)] == n ? 2 * a : 2 * a + 1; }
    i32 degree(i32 n) const { return degree_[z(n)]; }
    template <class F>
    void for_each(i32 n, F&& f) const {
        for (i32 sl = head_[z(n)]; sl != kNone; sl = next_[z(sl)]) f(sl / 2);
    }
    void arcs(i32 n, std::vector<i32>& out) const {
        out.clear();
        for_each(n, [&](i32 a) { out.push_back(a); });
    }

  private:
    std::vector<i32> head_, degree_, next_, prev_, owner_;
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

class Simplifier {
  public:
    Simplifier(const TriangleMesh& mesh, const ReebGraph& g, const SimplifyOptions& options)
        : g_(g), options_(options) {
        const std::size_t nn = g.node_count(), na = g.arc_count();
        value_ = g.node_values;
        area_ = node_areas(mesh, g);
        total_area_ = 0;
        for (const double a : area_) total_area_ += a;
        if (total_area_ <= 0) total_area_ = 1;
        forward_.assign(nn, kNone);
        critical_.resize(nn);
        modified_.assign(nn, 0);
        for (std::size_t n = 0; n < nn; ++n) critical_[n] = g.node_kinds[n] != NodeKind::regular;
        prev_.assign(nn, kNone);
        next_.assign(nn, kNone);
        inc_.init(nn, na);
        down_.assign(nn, 0);
        arcs_.resize(na);
        for (std::size_t a = 0; a < na; ++a) {
            Arc& arc = arcs_[a];
            arc.end = g.arcs[a];
            inc_.link(static_cast<i32>(2 * a), arc.end[0]);
            inc_.link(static_cast<i32>(2 * a + 1), arc.end[1]);
            ++down_[z(arc.end[1])];
            for (i32 i = g.arc_offsets[a]; i < g.arc_offsets[a + 1]; ++i) {
                const i32 r = g.arc_nodes[z(i)];
                if (arc.tail == kNone)
                    arc.head = r;
                else
                    next_[z(arc.tail)] = r, prev_[z(r)] = arc.tail;
                arc.tail = r;
                arc.area += area_[z(r)];
            }
        }
    }

    void run(const ProgressFn& progress, SimplifyResult& result) {
        for (std::size_t a = 0; a < arcs_.size(); ++a) consider(static_cast<i32>(a));
        const std::size_t initial = candidates_;
        std::size_t done = 0;
        while (!heap_.empty()) {
            const std::uint64_t key = heap_.pop();
            const i32 a = static_cast<i32>(key & 0xffffffffu);
            if (arcs_[z(a)].queued != key) continue;
            arcs_[z(a)].queued = 0;
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
    struct Arc {
        std::array<i32, 2> end{kNone, kNone};  // {lower, upper}
        i32 head = kNone, tail = kNone;        // regular nodes, lower to upper
        double area = 0;                       // area of the regular nodes' vertices
        std::uint64_t queued = 0;              // key of its live heap entry, 0 when none
        bool alive = true;
    };
    // Heap key: the persistence's order-preserving bits, then the arc id (ties by id).
    static std::uint64_t key_of(float persistence, i32 a) {
        return (std::uint64_t{std::bit_cast<std::uint32_t>(persistence)} << 32) |
               static_cast<std::uint32_t>(a);
    }

    // Arcs below and above a node: its arcs ending there as the upper / lower end (down_ is
    // updated wherever an arc end moves or an arc turns around).
    i32 down(i32 n) const { return down_[z(n)]; }
    i32 up(i32 n) const { return inc_.degree(n) - down_[z(n)]; }
    bool extremum(i32 n) const { return down(n) == 0 || up(n) == 0; }
    float persistence(i32 a) const {
        const Arc& arc = arcs_[z(a)];
        return std::fabs(value_[z(arc.end[1])] - value_[z(arc.end[0])]);
    }
    double area_ratio(i32 a) const {
        const Arc& arc = arcs_[z(a)];
        double s = arc.area;
        for (const i32 n : arc.end) s += area_[z(n)] / static_cast<double>(inc_.degree(n));
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
        Arc& arc = arcs_[z(a)];
        if (!candidate(a)) {
            arc.queued = 0;
            return;
        }
        const std::uint64_t key = key_of(persistence(a), a);
        if (arc.queued == key) return;
        arc.queued = key;
        heap_.push(key);
        ++candidates_;
    }

    // Node n's vertices (and everything already forwarded to it) join `keep`.
    void absorb(i32 n, i32 keep) {
        forward_[z(n)] = keep;
        area_[z(keep)] += area_[z(n)];
        critical_[z(n)] = false;
    }
    void absorb_list(Arc& arc, i32 keep) {
        for (i32 r = arc.head; r != kNone; r = next_[z(r)]) absorb(r, keep);
        arc.head = arc.tail = kNone;
        arc.area = 0;
    }

    // Arc b now ends at keep (whose value may have changed): regular nodes outside the new
    // value range join keep, and the ends swap if the other end is now on the wrong side.
    void fit_arc(i32 b, i32 keep) {
        Arc& arc = arcs_[z(b)];
        const float fk = value_[z(keep)];
        if (arc.end[1] == keep) {
            while (arc.tail != kNone && value_[z(arc.tail)] > fk) {
                const i32 r = arc.tail;
                arc.tail = prev_[z(r)];
                if (arc.tail == kNone)
                    arc.head = kNone;
                else
                    next_[z(arc.tail)] = kNone;
                arc.area -= area_[z(r)];
                absorb(r, keep);
            }
            if (value_[z(arc.end[0])] > fk) {
                absorb_list(arc, keep);
                ++down_[z(arc.end[0])];
                --down_[z(keep)];
                std::swap(arc.end[0], arc.end[1]);
            }
        } else {
            while (arc.head != kNone && value_[z(arc.head)] < fk) {
                const i32 r = arc.head;
                arc.head = next_[z(r)];
                if (arc.head == kNone)
                    arc.tail = kNone;
                else
                    prev_[z(arc.head)] = kNone;
                arc.area -= area_[z(r)];
                absorb(r, keep);
            }
            if (value_[z(arc.end[1])] < fk) {
                absorb_list(arc, keep);
                --down_[z(arc.end[1])];
                ++down_[z(keep)];
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
        const double share_before = area_[z(keep0)] / static_cast<double>(inc_.degree(keep0));
        const bool ext_before = extremum(keep0);
        if (lo_ext && hi_ext) {
            keep = lo;
            gone = hi;
            value_[z(keep)] = 0.5f * (value_[z(lo)] + value_[z(hi)]);
            ++result.extremum_extremum;
        } else {
            keep = lo_ext ? hi : lo;
            gone = lo_ext ? lo : hi;
            ++result.saddle_extremum;
        }
        modified_[z(keep)] = 1;
        arc.alive = false;
        inc_.unlink(2 * a);
        inc_.unlink(2 * a + 1);
        --down_[z(hi)];
        absorb_list(arc, keep);
        absorb(gone, keep);
        std::vector<i32>& touched = touched_;
        inc_.arcs(gone, touched);
        for (const i32 b : touched) {
            Arc& other = arcs_[z(b)];
            inc_.move(inc_.slot(b, gone), keep);
            for (auto& e : other.end)
                if (e == gone) e = keep;
            down_[z(keep)] += other.end[1] == keep;
        }
        down_[z(gone)] = 0;
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
            inc_.degree(keep) == 0 ? 0.0 : area_[z(keep)] / static_cast<double>(inc_.degree(keep));
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
                prev_[z(keep)] = L.tail;
                next_[z(keep)] = U.head;
                if (L.tail == kNone)
                    L.head = keep;
                else
                    next_[z(L.tail)] = keep;
                if (U.head != kNone) prev_[z(U.head)] = keep;
                L.tail = U.tail == kNone ? keep : U.tail;
                L.area += area_[z(keep)] + U.area;
                const i32 q = U.end[1];
                L.end[1] = q;
                U.alive = false;
                inc_.unlink(inc_.slot(upper, q));
                inc_.unlink(inc_.slot(upper, keep));
                inc_.move(inc_.slot(lower, keep), q);
                down_[z(keep)] = 0;
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
        auto root = [&](i32 n) {
            i32 r = n;
            while (forward_[z(r)] != kNone) r = forward_[z(r)];
            while (forward_[z(n)] != kNone) {
                const i32 nx = forward_[z(n)];
                forward_[z(n)] = r;
                n = nx;
            }
            return r;
        };
        std::vector<i32> new_id(nn, kNone);
        i32 count = 0;
        for (std::size_t n = 0; n < nn; ++n)
            if (forward_[n] == kNone) new_id[n] = count++;
        ReebGraph& out = result.graph;
        out.node_values.resize(z(count));
        out.node_kinds.assign(z(count), NodeKind::regular);
        out.node_lower_links.assign(z(count), 1);
        out.node_upper_links.assign(z(count), 1);
        out.node_arcs.assign(z(count), kNone);
        // Vertices: grouped by new node, in the order of their old nodes.
        std::vector<i32> size(z(count) + 1, 0);
        std::vector<i32> old_root(nn);
        for (std::size_t n = 0; n < nn; ++n) {
            old_root[n] = new_id[z(root(static_cast<i32>(n)))];
            size[z(old_root[n]) + 1] += g_.node_vertex_offsets[n + 1] - g_.node_vertex_offsets[n];
        }
        for (std::size_t i = 1; i < size.size(); ++i) size[i] += size[i - 1];
        out.node_vertex_offsets = size;
        out.node_vertices.resize(g_.node_vertices.size());
        out.vertex_nodes.resize(g_.vertex_nodes.size());
        result.field.resize(g_.vertex_nodes.size());
        for (std::size_t n = 0; n < nn; ++n) {
            const i32 nid = old_root[n];
            for (i32 i = g_.node_vertex_offsets[n]; i < g_.node_vertex_offsets[n + 1]; ++i) {
                const i32 v = g_.node_vertices[z(i)];
                out.node_vertices[z(size[z(nid)]++)] = v;
                out.vertex_nodes[z(v)] = nid;
            }
        }
        for (std::size_t n = 0; n < nn; ++n) {
            if (new_id[n] == kNone) continue;
            out.node_values[z(new_id[n])] = value_[n];
            if (!critical_[n]) continue;
            const i32 d = down(static_cast<i32>(n)), u = up(static_cast<i32>(n));
            out.node_kinds[z(new_id[n])] = d == 0   ? NodeKind::minimum
                                           : u == 0 ? NodeKind::maximum
                                                    : NodeKind::saddle;
            const bool unchanged = !modified_[n];
            out.node_lower_links[z(new_id[n])] =
                unchanged ? g_.node_lower_links[n] : static_cast<std::uint8_t>(std::min(d, 255));
            out.node_upper_links[z(new_id[n])] =
                unchanged ? g_.node_upper_links[n] : static_cast<std::uint8_t>(std::min(u, 255));
        }
        for (std::size_t v = 0; v < result.field.size(); ++v)
            result.field[v] = out.node_values[z(out.vertex_nodes[v])];
        out.arc_offsets.assign(1, 0);
        for (const Arc& arc : arcs_) {
            if (!arc.alive) continue;
            const i32 id = static_cast<i32>(out.arcs.size());
            out.arcs.push_back({new_id[z(arc.end[0])], new_id[z(arc.end[1])]});
            for (i32 r = arc.head; r != kNone; r = next_[z(r)]) {
                out.arc_nodes.push_back(new_id[z(r)]);
                out.node_arcs[z(new_id[z(r)])] = id;
            }
            out.arc_offsets.push_back(static_cast<i32>(out.arc_nodes.size()));
        }
    }

    const ReebGraph& g_;
    SimplifyOptions options_;
    std::vector<float> value_;
    std::vector<double> area_;
    double total_area_ = 0;
    std::vector<i32> forward_, prev_, next_, down_;
    std::vector<char> critical_, modified_;
    Incidence inc_;
    std::vector<i32> touched_, all_;
    std::vector<Arc> arcs_;
    KeyQueue heap_;
    std::size_t candidates_ = 0;  // keys pushed
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
