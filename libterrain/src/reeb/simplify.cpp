// Critical-node cancellation on a Reeb graph (docs/reeb.md). The graph is copied into a
// mutable form laid out for few cache misses: nodes renumbered, critical nodes first (one
// 64-byte record each: value, area, flags, arc counts and its arcs, up to 8 in the record,
// more in a run of a shared arena), then the regular nodes in the order of the arcs' lists,
// so that each list starts out contiguous; regular nodes in doubly linked lists (one per arc,
// sorted by value). A list absorbed whole is never walked: its area moves at once and its
// nodes learn where they went in the output, through sets of lists (see Arc). Candidates are
// keyed by (persistence, arc id): the first ones sorted once and read in order, later keys in
// a 4-ary heap; an arc whose key changes or that stops being a candidate leaves its old
// entry behind, and a taken arc is checked again before it is cancelled.

#include "terrain/reeb/simplify.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

#include "../core/indices.hpp"
#include "../core/release.hpp"
#include "terrain/core/error.hpp"

namespace terrain::reeb {

namespace {

using detail::i32;
using detail::idx;
using detail::kNone;

// Passes that gather from or scatter to random places start fetching them this many steps
// ahead.
constexpr std::size_t kAhead = 16;

// Queued arcs by key (persistence bits, then the arc id in the low half), in two parts: the
// first candidates, sorted once and read in order (most of them are cancelled with the key
// they started with), and a 4-ary min-heap for the keys set later, each arc at most once there
// (re-keying moves its entry). An arc re-keyed or dropped leaves its sorted entry behind: the
// caller, who knows each arc's current key, skips such entries.
class ArcQueue {
  public:
    static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // above any key

    void init(std::size_t arcs) { at_.assign(arcs, kNone); }
    void release() {
        detail::release(at_);
        detail::release(heap_);
        detail::release(sorted_);
    }
    // The first candidates, in any order, then sorted by seal().
    void seed(std::uint64_t key) { sorted_.push_back(key); }
    void seal() {
        // Seeded in increasing arc order: a stable sort of the high halves sorts the keys.
        std::vector<std::uint64_t> tmp(sorted_.size());
        for (const int shift : {32, 43, 54}) {
            std::array<std::size_t, 2048> count{};
            for (const std::uint64_t k : sorted_) ++count[(k >> shift) & 2047];
            std::size_t sum = 0;
            for (std::size_t& c : count) sum += std::exchange(c, sum);
            for (const std::uint64_t k : sorted_) tmp[count[(k >> shift) & 2047]++] = k;
            sorted_.swap(tmp);
        }
        next_ = 0;
    }
    // The next sorted entry (kEmpty after the last), and the one `ahead` places further.
    std::uint64_t sorted_front() const { return next_ < sorted_.size() ? sorted_[next_] : kEmpty; }
    std::uint64_t sorted_ahead(std::size_t ahead) const {
        return next_ + ahead < sorted_.size() ? sorted_[next_ + ahead] : kEmpty;
    }
    void skip_sorted() { ++next_; }
    std::uint64_t top() const { return heap_.empty() ? kEmpty : heap_.front(); }
    // Queues arc `key & 0xffffffff` with this key, or moves it there.
    void set(std::uint64_t key) {
        const std::size_t a = arc(key);
        if (at_[a] == kNone) {
            heap_.push_back(key);
            up(heap_.size() - 1, key);
        } else if (key < heap_[idx(at_[a])]) {
            up(idx(at_[a]), key);
        } else {
            down(idx(at_[a]), key);
        }
    }
    void erase(i32 a) {
        const i32 i = at_[idx(a)];
        if (i == kNone) return;
        at_[idx(a)] = kNone;
        const std::uint64_t last = heap_.back();
        heap_.pop_back();
        if (idx(i) == heap_.size()) return;
        if (last < heap_[idx(i)])
            up(idx(i), last);
        else
            down(idx(i), last);
    }
    // The root's hole goes down to a leaf along the smaller children, and the last entry
    // comes up from there (it mostly belongs near the leaves).
    std::uint64_t pop() {
        const std::uint64_t key = heap_.front(), last = heap_.back();
        at_[arc(key)] = kNone;
        heap_.pop_back();
        const std::size_t n = heap_.size();
        if (n == 0) return key;
        std::size_t i = 0;
        for (std::size_t m; (m = smallest_child(i)) != 0; i = m) place(i, heap_[m]);
        up(i, last);
        return key;
    }

  private:
    static std::size_t arc(std::uint64_t key) { return static_cast<std::uint32_t>(key); }
    void place(std::size_t i, std::uint64_t key) {
        heap_[i] = key;
        at_[arc(key)] = static_cast<i32>(i);
    }
    // Puts `key` at slot i or above (below) it, moving the entries in its way.
    void up(std::size_t i, std::uint64_t key) {
        while (i > 0) {
            const std::size_t parent = (i - 1) / 4;
            if (heap_[parent] <= key) break;
            place(i, heap_[parent]);
            i = parent;
        }
        place(i, key);
    }
    void down(std::size_t i, std::uint64_t key) {
        for (std::size_t m; (m = smallest_child(i)) != 0 && heap_[m] < key; i = m)
            place(i, heap_[m]);
        place(i, key);
    }
    // The slot of i's smallest child, 0 when it has none.
    std::size_t smallest_child(std::size_t i) const {
        const std::size_t c = 4 * i + 1, n = heap_.size();
        if (c >= n) return 0;
        std::size_t m = c;
        for (std::size_t j = c + 1; j < std::min(c + 4, n); ++j)
            if (heap_[j] < heap_[m]) m = j;
        return m;
    }

    std::vector<std::uint64_t> heap_;
    std::vector<i32> at_;  // each arc's slot in heap_, kNone when not there
    std::vector<std::uint64_t> sorted_;
    std::size_t next_ = 0;  // sorted_[next_ ..] are still to come
};

// The root of x in a forest of parent links (kNone at a root); the path is compressed.
i32 find_root(std::vector<i32>& parent, i32 x) {
    i32 root = x;
    while (parent[idx(root)] != kNone) root = parent[idx(root)];
    while (x != root) {
        const i32 up = parent[idx(x)];
        parent[idx(x)] = root;
        x = up;
    }
    return root;
}

std::vector<double> node_areas(const TriangleMesh& mesh, const ReebGraph& g) {
    std::vector<double> area(g.node_count(), 0.0);
    for (std::size_t v = 0; v < g.vertex_nodes.size(); ++v)
        area[idx(g.vertex_nodes[v])] += mesh.vertex_areas.empty() ? 1.0 : mesh.vertex_areas[v];
    return area;
}

// The summed area of node n's vertices, added in increasing vertex order (as a sweep over
// the vertices would add them).
double node_area(const TriangleMesh& mesh, const ReebGraph& g, std::size_t n,
                 std::vector<i32>& scratch) {
    const i32* v = g.node_vertices.data() + g.node_vertex_offsets[n];
    const std::size_t count = idx(g.node_vertex_offsets[n + 1] - g.node_vertex_offsets[n]);
    if (!std::is_sorted(v, v + count)) {
        scratch.assign(v, v + count);
        std::sort(scratch.begin(), scratch.end());
        v = scratch.data();
    }
    double s = 0;
    for (std::size_t i = 0; i < count; ++i)
        s += mesh.vertex_areas.empty() ? 1.0 : mesh.vertex_areas[idx(v[i])];
    return s;
}

// Nodes are numbered anew: first the nodes that are in no arc's list (the critical ones, the
// only possible arc ends), in their order, then the listed regular nodes in the order of
// arc_nodes.
class Simplifier {
  public:
    Simplifier(const TriangleMesh& mesh, const ReebGraph& g, const SimplifyOptions& options)
        : g_(g), options_(options) {
        const std::size_t nn = g.node_count(), na = g.arc_count(), nl = g.arc_nodes.size();
        // at_[n]: arc ends marked, the other regular nodes of the lists by their position in
        // arc_nodes (`placed` says which positions hold their node); then the new numbers.
        constexpr i32 kEnd = -2;
        at_.assign(nn, kNone);
        for (const auto& e : g.arcs) at_[idx(e[0])] = at_[idx(e[1])] = kEnd;
        std::vector<char> placed(nl, 0);
        for (std::size_t p = 0; p < nl; ++p) {
            const i32 r = g.arc_nodes[p];
            // (A critical node in a list keeps its neighbours in its record, which an arc end
            // needs for its arcs.)
            if (at_[idx(r)] != kNone)
                throw Error("simplify", "the graph is not valid: node " + std::to_string(r) +
                                            " is an arc end or in two arcs' lists");
            if (g.node_kinds[idx(r)] != NodeKind::regular) continue;
            at_[idx(r)] = static_cast<i32>(p);
            placed[p] = 1;
        }
        first_ = 0;
        for (const i32 i : at_) first_ += i < 0;
        crit_.resize(idx(first_));
        reg_.resize(nl);
        total_area_ = 0;
        std::vector<i32> scratch;
        i32 k = 0;
        for (std::size_t n = 0; n < nn; ++n) {
            if (n + kAhead < nn) {
                const std::size_t m = n + kAhead;
                const i32 i = g.node_vertex_offsets[m];
                if (!mesh.vertex_areas.empty() && i < g.node_vertex_offsets[m + 1])
                    __builtin_prefetch(&mesh.vertex_areas[idx(g.node_vertices[idx(i)])]);
                if (at_[m] >= 0) __builtin_prefetch(&reg_[idx(at_[m])], 1);
            }
            const double area = node_area(mesh, g, n, scratch);
            total_area_ += area;
            if (at_[n] < 0) {
                crit_[idx(k)].area = area;
                crit_[idx(k)].value = g.node_values[n];
                crit_[idx(k)].flags = g.node_kinds[n] != NodeKind::regular ? kCritical : 0;
                at_[n] = k++;
            } else {
                reg_[idx(at_[n])].area = area;
                reg_[idx(at_[n])].value = g.node_values[n];
                at_[n] += first_;
            }
        }
        if (total_area_ <= 0) total_area_ = 1;
        // Arc a joins its lower then its upper end, a in order.
        arcs_.resize(na);
        set_parent_.assign(na, kNone);
        set_fate_.assign(na, kNone);
        queue_.init(na);
        for (std::size_t a = 0; a < na; ++a) {
            Arc& arc = arcs_[a];
            if (a + kAhead < na)
                for (const i32 e : g.arcs[a + kAhead]) __builtin_prefetch(&at_[idx(e)]);
            if (a + kAhead / 2 < na)
                for (const i32 e : g.arcs[a + kAhead / 2])
                    __builtin_prefetch(&crit_[idx(at_[idx(e)])], 1);
            arc.end = {at_[idx(g.arcs[a][0])], at_[idx(g.arcs[a][1])]};
            for (const i32 e : arc.end) link(static_cast<i32>(a), e);
            ++crit_[idx(arc.end[1])].down;
            arc.set = static_cast<i32>(a);
            for (i32 p = g.arc_offsets[a]; p < g.arc_offsets[a + 1]; ++p) {
                const i32 r = placed[idx(p)] ? first_ + p : at_[idx(g.arc_nodes[idx(p)])];
                forward(r) = -2 - arc.set;
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
    }

    void run(const ProgressFn& progress, SimplifyResult& result) {
        for (std::size_t a = 0; a < arcs_.size(); ++a) {
            if (a + kAhead < arcs_.size())
                for (const i32 e : arcs_[a + kAhead].end) __builtin_prefetch(&crit_[idx(e)]);
            if (!candidate(static_cast<i32>(a))) continue;
            queue_.seed(mark_queued(static_cast<i32>(a)));
            ++pushed_;
        }
        queue_.seal();
        const std::size_t initial = pushed_;
        std::size_t done = 0;
        for (std::uint64_t key; (key = take()) != ArcQueue::kEmpty;) {
            const i32 a = static_cast<i32>(key & 0xffffffffu);
            // The sorted entries ahead are fetched, their arcs first, then their ends; the
            // heap's top arc is fetched while this one is handled, its ends after that.
            const std::uint64_t far = queue_.sorted_ahead(kAhead), near = queue_.sorted_ahead(4);
            if (far != ArcQueue::kEmpty) __builtin_prefetch(&arcs_[far & 0xffffffffu]);
            if (near != ArcQueue::kEmpty)
                for (const i32 e : arcs_[near & 0xffffffffu].end)
                    __builtin_prefetch(&crit_[idx(e)]);
            const std::uint64_t top = queue_.top();
            const std::size_t next = top == ArcQueue::kEmpty ? idx(a) : idx(top & 0xffffffffu);
            __builtin_prefetch(&arcs_[next]);
            arcs_[idx(a)].queued = kNotQueued;
            if (!candidate(a)) continue;
            cancel(redirect(a), result);
            for (const i32 e : arcs_[next].end) __builtin_prefetch(&crit_[idx(e)]);
            if ((++done & 0xfff) == 0 && initial > 0)
                report_progress(progress, std::min(0.9, 0.9 * done / static_cast<double>(initial)),
                                "simplify");
        }
        queue_.release();  // the output is the peak of memory: the queue is done
        output(result);
        report_progress(progress, 1.0, "simplify");
    }

  private:
    // A critical node (one of the first first_), in one cache line: its fields and its `size`
    // arcs, the newest last, with room for kInline << shift (see run()).
    static constexpr i32 kInline = 8;
    struct alignas(64) Crit {
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
    static_assert(sizeof(Crit) == 64);
    // A node's `forward`: the critical node that absorbed it; for a node in a list, -2 - the
    // set of its list (see Arc::set); kNone for a critical node.
    struct Reg {
        double area = 0;
        float value = 0;
        i32 forward = kNone;
        i32 prev = kNone, next = kNone;  // its neighbours in its arc's list
    };
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
    static constexpr std::uint32_t kNotQueued = ~std::uint32_t{0};  // no persistence's bits
    // Heap key: the persistence's order-preserving bits, then the arc id (ties by id).
    static std::uint64_t key_of(float persistence, i32 a) {
        return (std::uint64_t{std::bit_cast<std::uint32_t>(persistence)} << 32) |
               static_cast<std::uint32_t>(a);
    }

    // Any node's fields (a critical node's list neighbours are used once it is regular).
    double& area(i32 n) { return n < first_ ? crit_[idx(n)].area : reg_[idx(n - first_)].area; }
    float value(i32 n) const {
        return n < first_ ? crit_[idx(n)].value : reg_[idx(n - first_)].value;
    }
    i32& forward(i32 n) {
        return n < first_ ? crit_[idx(n)].forward : reg_[idx(n - first_)].forward;
    }
    i32& prev(i32 n) { return n < first_ ? crit_[idx(n)].own[0] : reg_[idx(n - first_)].prev; }
    i32& next(i32 n) { return n < first_ ? crit_[idx(n)].own[1] : reg_[idx(n - first_)].next; }

    // A critical node's arcs, the newest last: in its record while they fit, else in the arena.
    i32* run(Crit& c) { return c.shift == 0 ? c.own.data() : arena_.data() + c.offset; }
    const i32* run(const Crit& c) const {
        return c.shift == 0 ? c.own.data() : arena_.data() + c.offset;
    }
    // The arcs at a critical node, newest first.
    template <class F>
    void for_each_arc(i32 n, F&& f) const {
        const Crit& c = crit_[idx(n)];
        const i32* r = run(c);
        for (i32 i = c.size - 1; i >= 0; --i) f(r[i]);
    }
    void arcs_at(i32 n, std::vector<i32>& out) const {
        out.clear();
        for_each_arc(n, [&](i32 a) { out.push_back(a); });
    }
    // Arc a joins node n; a full run moves to the arena's end with twice the room.
    void link(i32 a, i32 n) {
        Crit& c = crit_[idx(n)];
        if (c.size == kInline << c.shift) {
            const i32 offset = static_cast<i32>(arena_.size());
            arena_.resize(arena_.size() + 2 * idx(c.size));
            std::copy_n(run(c), c.size, arena_.data() + offset);
            c.offset = offset;
            ++c.shift;
        }
        run(c)[c.size++] = a;
    }
    // Arc a leaves node n (the newest of its entries there, for an arc with both ends at n).
    void unlink(i32 a, i32 n) {
        Crit& c = crit_[idx(n)];
        if (c.size == 1) {  // its only arc
            c.size = 0;
            return;
        }
        i32* const last = run(c) + c.size;
        i32* it = last - 1;
        while (*it != a) --it;
        for (; it + 1 != last; ++it) *it = *(it + 1);
        --c.size;
    }

    // Arcs below and above a critical node: its arcs ending there as the upper / lower end
    // (`down` is updated wherever an arc end moves or an arc turns around).
    i32 degree(i32 n) const { return crit_[idx(n)].size; }
    i32 down(i32 n) const { return crit_[idx(n)].down; }
    i32 up(i32 n) const { return crit_[idx(n)].size - crit_[idx(n)].down; }
    bool extremum(i32 n) const { return down(n) == 0 || up(n) == 0; }
    float persistence(i32 a) const {
        const Arc& arc = arcs_[idx(a)];
        return std::fabs(crit_[idx(arc.end[1])].value - crit_[idx(arc.end[0])].value);
    }
    double area_ratio(i32 a) const {
        const Arc& arc = arcs_[idx(a)];
        double s = arc.area;
        for (const i32 n : arc.end) s += crit_[idx(n)].area / static_cast<double>(degree(n));
        return s / total_area_;
    }
    bool multi(i32 a) const {
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
    bool candidate(i32 a) const {
        const Arc& arc = arcs_[idx(a)];
        if (arc.set == kNone) return false;
        if (!extremum(arc.end[0]) && !extremum(arc.end[1])) return false;
        if (multi(a)) return false;
        return persistence(a) < options_.persistence || area_ratio(a) < options_.area_ratio / 100.0;
    }
    // Queues arc a with its current key if it is a candidate, else takes it out of the
    // queue.
    void consider(i32 a) {
        if (!candidate(a)) {
            arcs_[idx(a)].queued = kNotQueued;
            queue_.erase(a);
            return;
        }
        const std::uint64_t key = mark_queued(a);
        if (key == ArcQueue::kEmpty) return;
        queue_.set(key);
        ++pushed_;
    }
    // Records arc a as queued with its current key and returns the key; kEmpty if it was
    // queued with that key already.
    std::uint64_t mark_queued(i32 a) {
        const std::uint64_t key = key_of(persistence(a), a);
        std::uint32_t& queued = arcs_[idx(a)].queued;
        if (queued == key >> 32) return ArcQueue::kEmpty;
        queued = static_cast<std::uint32_t>(key >> 32);
        return key;
    }
    // The smallest current key queued, taken out (entries left behind are dropped on the way);
    // kEmpty when none is left.
    std::uint64_t take() {
        const auto current = [&](std::uint64_t key) {
            return arcs_[key & 0xffffffffu].queued == key >> 32;
        };
        for (;;) {
            std::uint64_t s = queue_.sorted_front();
            while (s != ArcQueue::kEmpty && !current(s)) {
                queue_.skip_sorted();
                s = queue_.sorted_front();
            }
            const std::uint64_t h = queue_.top();
            if (s == ArcQueue::kEmpty && h == ArcQueue::kEmpty) return ArcQueue::kEmpty;
            if (s < h) {
                queue_.skip_sorted();
                return s;
            }
            queue_.pop();
            if (current(h)) return h;  // else the twin of a sorted entry already taken
        }
    }
    // Node n's vertices (and everything already forwarded to it) join the critical node keep.
    void absorb(i32 n, i32 keep) {
        forward(n) = keep;
        crit_[idx(keep)].area += area(n);
    }
    // The regular nodes of an arc join keep, their area at once (the output tells them);
    // the arc, if it lives on, starts a new set.
    void absorb_list(Arc& arc, i32 keep, bool lives) {
        if (arc.head != kNone) {
            crit_[idx(keep)].area += arc.area;
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

    // Arc b now ends at keep (whose value may have changed): regular nodes outside the new
    // value range join keep, and the ends swap if the other end is now on the wrong side.
    void fit_arc(i32 b, i32 keep) {
        Arc& arc = arcs_[idx(b)];
        const float fk = crit_[idx(keep)].value;
        if (arc.end[1] == keep) {
            while (arc.tail != kNone && value(arc.tail) > fk) {
                const i32 r = arc.tail;
                arc.tail = prev(r);
                if (arc.tail == kNone)
                    arc.head = kNone;
                else
                    next(arc.tail) = kNone;
                arc.area -= area(r);
                absorb(r, keep);
            }
            if (crit_[idx(arc.end[0])].value > fk) {
                absorb_list(arc, keep, true);
                ++crit_[idx(arc.end[0])].down;
                --crit_[idx(keep)].down;
                turned_.push_back(arc.end[0]);
                std::swap(arc.end[0], arc.end[1]);
            }
        } else {
            while (arc.head != kNone && value(arc.head) < fk) {
                const i32 r = arc.head;
                arc.head = next(r);
                if (arc.head == kNone)
                    arc.tail = kNone;
                else
                    prev(arc.head) = kNone;
                arc.area -= area(r);
                absorb(r, keep);
            }
            if (crit_[idx(arc.end[1])].value < fk) {
                absorb_list(arc, keep, true);
                --crit_[idx(arc.end[1])].down;
                ++crit_[idx(keep)].down;
                turned_.push_back(arc.end[1]);
                std::swap(arc.end[0], arc.end[1]);
            }
        }
        if (arc.head == kNone) arc.area = 0;
    }

    // A critical node left with one arc below and one above becomes regular: its arcs merge
    // into the lower one (unless they would close on themselves). The merged arc and the arcs
    // parallel to it go to `out`; returns whether n became regular.
    bool regularize(i32 n, std::vector<i32>& out) {
        if (degree(n) != 2 || down(n) != 1) return false;
        arcs_at(n, all_);
        i32 lower = all_[0], upper = all_[1];
        if (arcs_[idx(lower)].end[1] != n) std::swap(lower, upper);
        Arc& L = arcs_[idx(lower)];
        Arc& U = arcs_[idx(upper)];
        if (L.end[0] == U.end[1]) return false;
        Crit& k = crit_[idx(n)];
        k.size = 0;  // its two arcs leave it, and its record takes its list neighbours
        k.down = 0;
        k.flags &= ~kCritical;
        k.forward = -2 - L.set;
        prev(n) = L.tail;
        next(n) = U.head;
        if (L.tail == kNone)
            L.head = n;
        else
            next(L.tail) = n;
        if (U.head != kNone) prev(U.head) = n;
        L.tail = U.tail == kNone ? n : U.tail;
        L.area += k.area + U.area;
        const i32 q = U.end[1];
        L.end[1] = q;
        set_parent_[idx(U.set)] = L.set;
        U.set = kNone;
        unlink(upper, q);
        link(lower, q);
        // The arcs parallel to the merged one, found at its end with fewer arcs (the one
        // multi() will look at too).
        out.push_back(lower);
        const i32 m = degree(L.end[0]) <= degree(L.end[1]) ? L.end[0] : L.end[1];
        for_each_arc(m, [&](i32 b) {
            const auto& e = arcs_[idx(b)].end;
            if (b != lower && e[0] == L.end[0] && e[1] == L.end[1]) out.push_back(b);
        });
        return true;
    }

    // The arc to cancel for candidate a. A degenerate extremum (several arcs) paired with a
    // saddle while another saddle next to it lies closer in value goes to the closer one:
    // keeping the farther one would turn the closer one's arc around, and flattening the
    // extremum to the farther value would cut across the closer saddle's branches (the
    // rewritten field would then disagree with the graph).
    i32 redirect(i32 a) const {
        const Arc& arc = arcs_[idx(a)];
        const i32 lo = arc.end[0], hi = arc.end[1];
        const bool lo_ext = down(lo) == 0, hi_ext = up(hi) == 0;
        if (lo_ext == hi_ext) return a;  // two extrema: their own rules
        const i32 ext = lo_ext ? lo : hi;
        if (degree(ext) < 2) return a;
        const float fe = crit_[idx(ext)].value;
        i32 best = a;
        float best_gap = std::fabs(crit_[idx(lo_ext ? hi : lo)].value - fe);
        for_each_arc(ext, [&](i32 b) {
            const auto& e = arcs_[idx(b)].end;
            const i32 other = e[0] == ext ? e[1] : e[0];
            const float gap = std::fabs(crit_[idx(other)].value - fe);
            if (gap < best_gap && !extremum(other) && !multi(b)) {
                best = b;
                best_gap = gap;
            }
        });
        return best;
    }

    void cancel(i32 a, SimplifyResult& result) {
        turned_.clear();
        Arc& arc = arcs_[idx(a)];
        const i32 lo = arc.end[0], hi = arc.end[1];
        const bool lo_ext = down(lo) == 0, hi_ext = up(hi) == 0;
        // Two extrema: they meet at the midpoint of their values, unless one of them has no
        // other arc and the other has more (a degenerate extremum, also a saddle): then the
        // first is absorbed into the second, which keeps its value, as a saddle would. The
        // midpoint there would move the degenerate extremum and turn its other arcs around,
        // and the rewritten field would no longer match the graph.
        const bool both = lo_ext && hi_ext;
        const bool midpoint = both && (degree(lo) == 1) == (degree(hi) == 1);
        i32 keep = lo;  // the midpoint, or a saddle (or degenerate extremum) below
        if (!midpoint && (both ? degree(lo) == 1 : lo_ext)) keep = hi;
        const i32 gone = keep == lo ? hi : lo;
        const double share_before = crit_[idx(keep)].area / static_cast<double>(degree(keep));
        const bool ext_before = extremum(keep);
        if (midpoint) crit_[idx(keep)].value = 0.5f * (crit_[idx(lo)].value + crit_[idx(hi)].value);
        ++(both ? result.extremum_extremum : result.saddle_extremum);
        Crit& k = crit_[idx(keep)];
        k.flags |= kModified;
        unlink(a, lo);
        unlink(a, hi);
        --crit_[idx(hi)].down;
        absorb_list(arc, keep, false);
        arc.set = kNone;
        absorb(gone, keep);
        std::vector<i32>& touched = touched_;
        arcs_at(gone, touched);
        crit_[idx(gone)].size = 0;
        crit_[idx(gone)].down = 0;
        for (const i32 b : touched) {
            Arc& other = arcs_[idx(b)];
            link(b, keep);
            for (auto& e : other.end)
                if (e == gone) e = keep;
            k.down += other.end[1] == keep;
        }
        if (midpoint) {
            arcs_at(keep, all_);
            for (const i32 b : all_) fit_arc(b, keep);
        } else {
            for (const i32 b : touched) fit_arc(b, keep);
        }
        // keep's other arcs need a new look only if they may have become candidates: its
        // value moved, it became an extremum, or its area share per arc went down. Arcs that
        // stopped being candidates are dropped when they reach the top of the heap.
        const double share_after =
            degree(keep) == 0 ? 0.0 : k.area / static_cast<double>(degree(keep));
        if (midpoint || extremum(keep) != ext_before || share_after < share_before)
            arcs_at(keep, touched);

        merged_.clear();
        if (regularize(keep, merged_)) touched.swap(merged_);
        // An arc turned around moves one arc end at its far node from above to below or back:
        // that node may now be regular, or an extremum whose arcs are new candidates.
        for (const i32 n : turned_) {
            if (degree(n) == 0) continue;
            crit_[idx(n)].flags |= kModified;
            if (!regularize(n, touched)) for_each_arc(n, [&](i32 b) { touched.push_back(b); });
        }
        for (const i32 b : touched) consider(b);
    }

    void output(SimplifyResult& result) {
        const std::size_t nn = g_.node_count(), nl = reg_.size();
        // code[i]: for an absorbed node, the critical node that finally took it (nodes are
        // only absorbed into critical nodes); for a remaining node, -2 - its new id.
        // A listed node's forward: the fate of its set's root (kNone for a list still there).
        const auto fate = [&](i32 f) {
            return f > -2 ? f : set_fate_[idx(find_root(set_parent_, -2 - f))];
        };
        std::vector<i32> code(idx(first_) + nl);
        for (std::size_t k = 0; k < idx(first_); ++k) code[k] = fate(crit_[k].forward);
        for (std::size_t k = 0; k < idx(first_); ++k)
            if (code[k] != kNone) code[k] = find_root(code, code[k]);
        for (std::size_t p = 0; p < nl; ++p) {
            const i32 f = fate(reg_[p].forward);
            code[idx(first_) + p] = f == kNone || code[idx(f)] == kNone ? f : code[idx(f)];
        }
        // The remaining nodes are numbered in the order of the old ones; at_ takes each old
        // node's new node (first -2 - the node that took it, for the absorbed ones).
        std::vector<std::array<i32, 2>> kept;  // {old node, internal index} by new id
        for (std::size_t n = 0; n < nn; ++n) {
            if (n + kAhead < nn) __builtin_prefetch(&code[idx(at_[n + kAhead])]);
            i32& c = code[idx(at_[n])];
            if (c != kNone) {
                at_[n] = -2 - c;
                continue;
            }
            c = -2 - static_cast<i32>(kept.size());
            kept.push_back({static_cast<i32>(n), at_[n]});
            at_[n] = -2 - c;
        }
        const std::size_t count = kept.size();
        std::vector<i32> size(count + 1, 0);
        for (std::size_t n = 0; n < nn; ++n) {
            if (at_[n] < 0) at_[n] = -2 - code[idx(-2 - at_[n])];
            size[idx(at_[n]) + 1] += g_.node_vertex_offsets[n + 1] - g_.node_vertex_offsets[n];
        }
        ReebGraph& out = result.graph;
        out.node_values.resize(count);
        out.node_kinds.assign(count, NodeKind::regular);
        out.node_lower_links.assign(count, 1);
        out.node_upper_links.assign(count, 1);
        out.node_arcs.assign(count, kNone);
        for (std::size_t nid = 0; nid < count; ++nid) {
            const auto [n, i] = kept[nid];
            out.node_values[nid] = value(i);
            if (i >= first_ || !(crit_[idx(i)].flags & kCritical)) continue;
            const i32 d = down(i), u = up(i);
            out.node_kinds[nid] = d == 0   ? NodeKind::minimum
                                  : u == 0 ? NodeKind::maximum
                                           : NodeKind::saddle;
            const bool unchanged = !(crit_[idx(i)].flags & kModified);
            out.node_lower_links[nid] = unchanged ? g_.node_lower_links[idx(n)]
                                                  : static_cast<std::uint8_t>(std::min(d, 255));
            out.node_upper_links[nid] = unchanged ? g_.node_upper_links[idx(n)]
                                                  : static_cast<std::uint8_t>(std::min(u, 255));
        }
        // Vertices: grouped by new node, in the order of their old nodes.
        for (std::size_t i = 1; i < size.size(); ++i) size[i] += size[i - 1];
        out.node_vertex_offsets = size;
        out.node_vertices.resize(g_.node_vertices.size());
        out.vertex_nodes.resize(g_.vertex_nodes.size());
        for (std::size_t n = 0; n < nn; ++n) {
            if (n + kAhead < nn) {
                const i32 i = g_.node_vertex_offsets[n + kAhead];
                if (i < g_.node_vertex_offsets[n + kAhead + 1])
                    __builtin_prefetch(&out.vertex_nodes[idx(g_.node_vertices[idx(i)])], 1);
            }
            const i32 nid = at_[n];
            for (i32 i = g_.node_vertex_offsets[n]; i < g_.node_vertex_offsets[n + 1]; ++i) {
                const i32 v = g_.node_vertices[idx(i)];
                out.node_vertices[idx(size[idx(nid)]++)] = v;
                out.vertex_nodes[idx(v)] = nid;
            }
        }
        result.field.resize(g_.vertex_nodes.size());
        for (std::size_t v = 0; v < result.field.size(); ++v)
            result.field[v] = out.node_values[idx(out.vertex_nodes[v])];
        const auto new_id = [&](i32 i) { return -2 - code[idx(i)]; };
        out.arc_offsets.assign(1, 0);
        for (const Arc& arc : arcs_) {
            if (arc.set == kNone) continue;
            const i32 id = static_cast<i32>(out.arcs.size());
            out.arcs.push_back({new_id(arc.end[0]), new_id(arc.end[1])});
            for (i32 r = arc.head; r != kNone; r = next(r)) {
                const i32 nid = new_id(r);
                out.arc_nodes.push_back(nid);
                out.node_arcs[idx(nid)] = id;
            }
            out.arc_offsets.push_back(static_cast<i32>(out.arc_nodes.size()));
        }
    }

    const ReebGraph& g_;
    SimplifyOptions options_;
    std::vector<i32> at_;  // each node's new number
    i32 first_ = 0;        // critical nodes: 0 .. first_ - 1
    std::vector<Crit> crit_;
    std::vector<Reg> reg_;  // node first_ + i is reg_[i]
    std::vector<i32> arena_;
    double total_area_ = 0;
    std::vector<i32> touched_, all_, merged_;
    std::vector<i32> turned_;      // far ends of the arcs fit_arc turned around
    std::vector<i32> set_parent_;  // of each set, kNone for a root (an arc's current set)
    std::vector<i32> set_fate_;    // of each root set: the node that absorbed it, or kNone
    std::vector<Arc> arcs_;
    ArcQueue queue_;
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
        m.persistence[a] = std::fabs(g.node_values[idx(hi)] - g.node_values[idx(lo)]);
        double s = area[idx(lo)] / static_cast<double>(inc.degree(lo)) +
                   area[idx(hi)] / static_cast<double>(inc.degree(hi));
        for (i32 i = g.arc_offsets[a]; i < g.arc_offsets[a + 1]; ++i)
            s += area[idx(g.arc_nodes[idx(i)])];
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

SimplifyResult simplify(const TriangleMesh& mesh, ReebGraph&& graph, const SimplifyOptions& options,
                        const ProgressFn& progress) {
    check_simplify_options(options);
    if (graph.vertex_nodes.size() != mesh.vertex_count())
        throw Error("simplify", "the graph was not built on this mesh");
    SimplifyResult result;
    Simplifier simplifier(mesh, graph, options);
    // The working copy holds the arcs now; the output reads only the vertex lists and links.
    detail::release(graph.arcs);
    detail::release(graph.arc_offsets);
    detail::release(graph.arc_nodes);
    detail::release(graph.node_arcs);
    detail::release(graph.node_kinds);
    simplifier.run(progress, result);
    return result;
}

}  // namespace terrain::reeb
