// The Reeb graph by a contour-tracking sweep (paper s.3.1: the graph follows the level set's
// contours as the value rises; docs/reeb.md "Construction"), for any 2-manifold mesh, with
// handles and holes. Our own algorithm in the family of Cole-McLaughlin et al. 2003 (loops in
// Reeb graphs of 2-manifolds).
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

#include "contour_sweep.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "event_order.hpp"
#include "half_edges.hpp"
#include "link_components.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/disjoint_sets.hpp"
#include "terrain/internal/core/indices.hpp"

namespace terrain::reeb::internal {

namespace {

using detail::i32;
using detail::idx;
using detail::kNone;

class Sweep {
  public:
    Sweep(const TriangleMesh& mesh, const std::vector<float>& field, ReebGraph& g)
        : mesh_(mesh), field_(field), g_(g) {}

    // `ordered`: the graph's events are already set (order_events).
    void run(const ProgressFn& progress, bool ordered);

  private:
    struct Contour {
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
    // An event general_event handles in six steps: the event's star (every triangle with a
    // corner in it, once, sorted), the contours entering it and their boundary ends inside the
    // star (and the node's links), the segments of the star's new mixed triangles and their
    // ends, every end settled (walked in lockstep), the groups of segments joined through
    // paired ends, and the new contours.
    void general_event(i32 e, i32 begin, i32 end);
    void event_star(i32 e, i32 begin, i32 end);
    void incoming_contours(i32 e);
    void event_segments(i32 e);
    void settle_ends(i32 e);
    void join_groups(i32 e);
    void new_contours(i32 e);
    // A piece is walked when one of its ends completed it.
    bool piece_done(const End& en) const;

    bool processed(i32 v, i32 e) const { return g_.vertex_nodes[idx(v)] <= e; }
    bool in_event(i32 t, i32 e) const {
        const auto& tri = mesh_.triangles()[idx(t)];
        return g_.vertex_nodes[idx(tri[0])] == e || g_.vertex_nodes[idx(tri[1])] == e ||
               g_.vertex_nodes[idx(tri[2])] == e;
    }
    // The contour a triangle's label now stands for (merged contours keep one id).
    i32 find(i32 label) { return contour_ids_.find(label); }
    i32 new_contour(i32 arc, i32 open) {
        contours_.push_back({arc, open});
        return contour_ids_.add();
    }
    i32 new_arc(i32 lower) {
        arcs_.push_back({lower, kNone, kNone, kNone, 0});
        return static_cast<i32>(arcs_.size() - 1);
    }
    void append_regular(i32 arc, i32 node) {
        auto& a = arcs_[idx(arc)];
        if (a.tail == kNone)
            a.head = node;
        else
            node_next_[idx(a.tail)] = node;
        a.tail = node;
        ++a.count;
        g_.node_arcs[idx(node)] = arc;
    }
    // One walk step from end i; returns 0 (going on), 1 (arrived at another end), 2 (boundary).
    int step(i32 i, i32 e);
    i32 end_at(i32 s_he) const;
    void deduce(i32 label);
    void finish_graph();

    const TriangleMesh& mesh_;
    const std::vector<float>& field_;
    ReebGraph& g_;
    HalfEdges half_edges_;
    std::vector<i32> tri_label_;
    std::vector<Contour> contours_;
    detail::DisjointSets<i32> contour_ids_;  // merged contours: one root id each
    std::vector<ArcBuild> arcs_;
    std::vector<i32> node_next_;

    // Scratch for general events, reused.
    std::vector<i32> star_, seg_bnd_, d_in_;
    detail::DisjointSets<i32> segments_;  // over star_: its triangles with an upper corner
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
    half_edges_ = build_half_edges(mesh_);
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
    if (end - begin == 1 && try_regular(e, g_.node_vertices[idx(begin)])) return;
    general_event(e, begin, end);
}

// The common case: a single vertex whose link has one lower and one upper run.
bool Sweep::try_regular(i32 e, i32 v) {
    const i32 h0 = half_edges_.vertex_out[idx(v)];
    if (h0 == kNone) return false;
    const bool boundary = half_edges_.twin[idx(h0)] == kNone;
    // Walk the fan: for each triangle, its corner after v (the link vertex) is `a`.
    int changes = 0, lower_runs = 0, upper_runs = 0;
    i32 label_tri = kNone;
    bool first_lower = false, last_lower = false;
    i32 h = h0;
    bool first = true;
    for (;;) {
        const i32 t = h / 3;
        const i32 a = mesh_.triangles()[idx(t)][idx((h + 1) % 3)];
        const bool lower = g_.vertex_nodes[idx(a)] < e;
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
        const i32 tw = half_edges_.twin[idx(in)];
        if (tw == kNone) {  // boundary: the last link vertex is the far corner of this triangle
            const i32 b = mesh_.triangles()[idx(t)][idx((h + 2) % 3)];
            const bool bl = g_.vertex_nodes[idx(b)] < e;
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
    const i32 c = find(tri_label_[idx(label_tri)]);
    // Relabel the triangles that stay mixed (those with an upper corner).
    h = h0;
    for (;;) {
        const i32 t = h / 3;
        const auto& tri = mesh_.triangles()[idx(t)];
        if (g_.vertex_nodes[idx(tri[0])] > e || g_.vertex_nodes[idx(tri[1])] > e ||
            g_.vertex_nodes[idx(tri[2])] > e)
            tri_label_[idx(t)] = c;
        const i32 tw = half_edges_.twin[idx(prev_he(h))];
        if (tw == kNone || tw == h0) break;
        h = tw;
    }
    g_.node_lower_links[idx(e)] = 1;
    g_.node_upper_links[idx(e)] = 1;
    append_regular(contours_[idx(c)].arc, e);
    return true;
}

i32 Sweep::end_at(i32 s_he) const {
    const auto it =
        std::lower_bound(end_index_.begin(), end_index_.end(), std::make_pair(s_he, kNone));
    return (it != end_index_.end() && it->first == s_he) ? it->second : kNone;
}

int Sweep::step(i32 i, i32 e) {
    End& en = ends_[idx(i)];
    const i32 t = en.cur / 3;
    const auto& tri = mesh_.triangles()[idx(t)];
    walks_[idx(en.walk)].push_back(t);
    i32 out = kNone;
    for (i32 k = 1; k <= 2; ++k) {
        const i32 j = (en.cur % 3 + k) % 3;
        if (processed(tri[idx(j)], e) != processed(tri[idx((j + 1) % 3)], e)) {
            out = 3 * t + j;
            break;
        }
    }
    if (out == kNone) throw Error("reeb", "internal error: a contour walk lost its way");
    const i32 nxt = half_edges_.twin[idx(out)];
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
                    en.state = ends_[idx(a)].state = 1;
                    en.partner = a;
                    ends_[idx(a)].partner = static_cast<i32>(i);
                }
            }
            lc.unresolved = 0;
        }
        return;
    }
}

void Sweep::event_star(i32 e, i32 begin, i32 end) {
    // 1. The star of the event: every triangle with a corner in it, once.
    star_.clear();
    for (i32 i = begin; i < end; ++i) {
        const i32 v = g_.node_vertices[idx(i)];
        const i32 h0 = half_edges_.vertex_out[idx(v)];
        if (h0 == kNone) continue;
        i32 h = h0;
        for (;;) {
            const i32 t = h / 3;
            // Keep the triangle only from its lowest-numbered corner in the event.
            i32 owner = v;
            for (const i32 c : mesh_.triangles()[idx(t)])
                if (g_.vertex_nodes[idx(c)] == e) owner = std::min(owner, c);
            if (owner == v) star_.push_back(t);
            const i32 tw = half_edges_.twin[idx(prev_he(h))];
            if (tw == kNone || tw == h0) break;
            h = tw;
        }
    }
    std::sort(star_.begin(), star_.end());
}

void Sweep::incoming_contours(i32 e) {
    // 2. Contours entering the event (before it is processed) and their boundary ends inside
    //    the star; the link components for the node's classification.
    d_in_.clear();
    label_counts_.clear();
    for (const i32 t : star_) {
        const auto& tri = mesh_.triangles()[idx(t)];
        bool has_lower = false;
        for (const i32 c : tri) has_lower |= g_.vertex_nodes[idx(c)] < e;
        if (!has_lower) continue;
        const i32 c = find(tri_label_[idx(t)]);
        tri_label_[idx(t)] = c;
        if (std::find(d_in_.begin(), d_in_.end(), c) == d_in_.end()) {
            d_in_.push_back(c);
            label_counts_.push_back({c, 0, contours_[idx(c)].open});
        }
        for (i32 j = 0; j < 3; ++j) {
            if (half_edges_.twin[idx(3 * t + j)] != kNone) continue;
            const bool pa = g_.vertex_nodes[idx(tri[idx(j)])] < e;
            const bool pb = g_.vertex_nodes[idx(tri[idx((j + 1) % 3)])] < e;
            if (pa != pb)
                for (auto& lc : label_counts_)
                    if (lc.label == c) --lc.need_boundary;
        }
    }
    set_links(g_, e, links_.count(mesh_, g_, e, star_));
}

void Sweep::event_segments(i32 e) {
    auto star_index = [&](i32 t) {
        return static_cast<i32>(std::lower_bound(star_.begin(), star_.end(), t) - star_.begin());
    };
    // 3. The event is processed from here on. Segments: new mixed triangles of the star joined
    //    across active edges; their exits into the old contours are the ends.
    const std::size_t ns = star_.size();
    segments_.reset_empty(ns);
    seg_bnd_.assign(ns, 0);
    auto in_segment = [&](std::size_t i) { return segments_.contains(static_cast<i32>(i)); };
    for (std::size_t i = 0; i < ns; ++i) {
        const auto& tri = mesh_.triangles()[idx(star_[i])];
        if (g_.vertex_nodes[idx(tri[0])] > e || g_.vertex_nodes[idx(tri[1])] > e ||
            g_.vertex_nodes[idx(tri[2])] > e)
            segments_.make_set(static_cast<i32>(i));
    }
    ends_.clear();
    end_index_.clear();
    std::size_t n_walks = 0;
    for (std::size_t i = 0; i < ns; ++i) {
        if (!in_segment(i)) continue;
        const i32 t = star_[i];
        const auto& tri = mesh_.triangles()[idx(t)];
        for (i32 j = 0; j < 3; ++j) {
            if (processed(tri[idx(j)], e) == processed(tri[idx((j + 1) % 3)], e)) continue;
            const i32 h = 3 * t + j;
            const i32 tw = half_edges_.twin[idx(h)];
            if (tw == kNone) {
                ++seg_bnd_[i];
            } else if (in_event(tw / 3, e)) {
                segments_.unite_to_smaller(static_cast<i32>(i), star_index(tw / 3));
            } else {
                const i32 label = find(tri_label_[idx(tw / 3)]);
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
}

void Sweep::settle_ends(i32 e) {
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
                    End& other = ends_[idx(en.partner)];
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
}

bool Sweep::piece_done(const End& en) const {
    return en.complete || (en.state == 1 && ends_[idx(en.partner)].complete);
}

void Sweep::join_groups(i32 e) {
    auto seg_root = [&](i32 x) { return segments_.find(x); };
    // 5. Groups: segments joined through paired ends. Each group is one new contour.
    for (const auto& en : ends_) {
        if (en.state != 1) continue;
        segments_.unite_to_smaller(en.segment, ends_[idx(en.partner)].segment);
    }
    // A piece is walked when one of its ends completed it; a label whose unwalked pieces lie in
    // several groups has all but one group's pieces walked to the end (lockstep again).
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
}

void Sweep::new_contours(i32 e) {
    const std::size_t ns = star_.size();
    auto seg_root = [&](i32 x) { return segments_.find(x); };
    auto in_segment = [&](std::size_t i) { return segments_.contains(static_cast<i32>(i)); };
    // 6. New contours: a group keeps the ids of the old contours whose unwalked pieces it holds
    //    (merged by union), or gets a new id; walked pieces and new triangles are relabelled.
    const bool regular = d_in_.size() == 1 && [&] {
        i32 only = kNone;
        for (std::size_t i = 0; i < ns; ++i)
            if (in_segment(i)) {
                if (only != kNone && seg_root(static_cast<i32>(i)) != only) return false;
                only = seg_root(static_cast<i32>(i));
            }
        return only != kNone;
    }();
    const i32 continuing_arc = regular ? contours_[idx(d_in_[0])].arc : kNone;
    if (!regular)
        for (const i32 c : d_in_) arcs_[idx(contours_[idx(c)].arc)].upper = e;
    int groups = 0;
    for (std::size_t i = 0; i < ns; ++i) {
        if (!in_segment(i) || seg_root(static_cast<i32>(i)) != static_cast<i32>(i)) continue;
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
                contour_ids_.unite(id, c);
        }
        for (std::size_t k = 0; k < ns; ++k)
            if (in_segment(k) && seg_root(static_cast<i32>(k)) == gr) open += seg_bnd_[k];
        const i32 arc = regular ? continuing_arc : new_arc(e);
        if (id == kNone)
            id = new_contour(arc, open);
        else
            contours_[idx(id)].arc = arc, contours_[idx(id)].open = open;
        for (const auto& en : ends_)
            if (seg_root(en.segment) == gr && en.complete)
                for (const i32 t : walks_[idx(en.walk)]) tri_label_[idx(t)] = id;
        for (std::size_t k = 0; k < ns; ++k)
            if (in_segment(k) && seg_root(static_cast<i32>(k)) == gr)
                tri_label_[idx(star_[k])] = id;
    }
    if (regular) {  // Reeb-regular (a boundary vertex may still have a split link)
        g_.node_lower_links[idx(e)] = g_.node_upper_links[idx(e)] = 1;
        append_regular(continuing_arc, e);
        return;
    }
    const auto d_down = d_in_.size();
    g_.node_kinds[idx(e)] = d_down == 0   ? NodeKind::minimum
                            : groups == 0 ? NodeKind::maximum
                                          : NodeKind::saddle;
}

void Sweep::general_event(i32 e, i32 begin, i32 end) {
    event_star(e, begin, end);
    incoming_contours(e);
    event_segments(e);
    settle_ends(e);
    join_groups(e);
    new_contours(e);
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
        for (i32 n = arcs_[a].head; n != kNone; n = node_next_[idx(n)])
            g_.arc_nodes[idx(pos++)] = n;
    }
}

}  // namespace

void contour_sweep(const TriangleMesh& mesh, const std::vector<float>& field, ReebGraph& g,
                   const ProgressFn& progress, bool ordered) {
    Sweep(mesh, field, g).run(progress, ordered);
}

}  // namespace terrain::reeb::internal
