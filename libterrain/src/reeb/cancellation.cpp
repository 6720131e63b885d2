// The cancellation rules of the simplification (paper s.3.2, METHOD.md s.4; the rule as a
// whole is told in simplify.cpp). A candidate arc is cancelled in one of two ways:
//   - saddle-extremum: the extremum, the arc and the arc's regular nodes are absorbed into the
//     saddle, which keeps its value;
//   - extremum-extremum: both ends become one node at the midpoint of their values (or, when
//     one of them is a degenerate extremum with other arcs, the other is absorbed into it).
// Afterwards the graph is made consistent again: the kept node's other arcs lose the regular
// nodes now outside their value range and turn around when their far end is now on the other
// side (fit_arc); a critical node left with one arc below and one above becomes regular and
// its two arcs merge (regularize); arcs that may have become candidates are queued again.

#include <cmath>
#include <utility>
#include <vector>

#include "simplifier.hpp"

namespace terrain::reeb::internal {

// Arc b now ends at keep (whose value may have changed): regular nodes outside the new
// value range join keep, and the ends swap if the other end is now on the wrong side.
void Simplifier::fit_arc(i32 b, i32 keep) {
    Arc& arc = arcs_[idx(b)];
    ends(b);  // live ends
    const float fk = critical_[idx(keep)].value;
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
        if (critical_[idx(arc.end[0])].value > fk) {
            absorb_list(arc, keep, true);
            ++critical_[idx(arc.end[0])].down;
            --critical_[idx(keep)].down;
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
        if (critical_[idx(arc.end[1])].value < fk) {
            absorb_list(arc, keep, true);
            --critical_[idx(arc.end[1])].down;
            ++critical_[idx(keep)].down;
            turned_.push_back(arc.end[1]);
            std::swap(arc.end[0], arc.end[1]);
        }
    }
    if (arc.head == kNone) arc.area = 0;
    refresh_ends(b);
}

// A critical node left with one arc below and one above becomes regular: its arcs merge
// into the lower one (unless they would close on themselves). The merged arc and the arcs
// parallel to it go to `out`; returns whether n became regular.
bool Simplifier::regularize(i32 n, std::vector<i32>& out) {
    if (degree(n) != 2 || down(n) != 1) return false;
    arcs_at(n, all_);
    i32 lower = all_[0], upper = all_[1];
    ends(upper);
    if (ends(lower)[1] != n) std::swap(lower, upper);
    Arc& L = arcs_[idx(lower)];
    Arc& U = arcs_[idx(upper)];
    if (L.end[0] == U.end[1]) return false;
    CriticalNode& k = critical_[idx(n)];
    k.size = 0;  // its two arcs leave it, and its record takes its list neighbours
    release_run(k);
    k.down = 0;
    k.flags &= ~kCritical;
    set_forward(n, -2 - L.set);
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
    refresh_ends(lower);  // its far end and nearest node changed at its lower end
    // The arcs parallel to the merged one, found at its end with fewer arcs (the one
    // has_parallel_arc() will look at too).
    out.push_back(lower);
    const i32 m = degree(L.end[0]) <= degree(L.end[1]) ? L.end[0] : L.end[1];
    for_each_arc(m, [&](i32 b) {
        const auto& e = ends(b);
        if (b != lower && e[0] == L.end[0] && e[1] == L.end[1]) out.push_back(b);
    });
    return true;
}

// The arc to cancel for candidate a. A degenerate extremum (several arcs) paired with a
// saddle while another saddle next to it lies closer in value goes to the closer one:
// keeping the farther one would turn the closer one's arc around, and flattening the
// extremum to the farther value would cut across the closer saddle's branches (the
// rewritten field would then disagree with the graph).
i32 Simplifier::redirect(i32 a) const {
    const auto [lo, hi] = ends(a);
    const bool lo_ext = down(lo) == 0, hi_ext = up(hi) == 0;
    if (lo_ext == hi_ext) return a;  // two extrema: their own rules
    const i32 ext = lo_ext ? lo : hi;
    if (degree(ext) < 2) return a;
    if (big(ext)) return redirect_big(a, ext);
    i32 best = a;
    float best_gap = persistence(a);
    for_each_arc(ext, [&](i32 b) {
        const auto& e = ends(b);
        const i32 other = e[0] == ext ? e[1] : e[0];
        const float gap = persistence(b);
        if (gap < best_gap && !extremum(other) && !has_parallel_arc(b)) {
            best = b;
            best_gap = gap;
        }
    });
    return best;
}

// Which end of candidate arc a stays and which goes. A saddle (or a degenerate extremum)
// stays and keeps its value. Two extrema meet at the midpoint of their values, the lower one
// staying, unless one of them has no other arc and the other has more (a degenerate
// extremum, also a saddle): then the first is absorbed into the second, which keeps its
// value, as a saddle would. The midpoint there would move the degenerate extremum and turn
// its other arcs around, and the rewritten field would no longer match the graph.
Simplifier::Pairing Simplifier::pairing(i32 a) const {
    const auto [lo, hi] = ends(a);
    const bool lo_ext = down(lo) == 0, hi_ext = up(hi) == 0;
    Pairing p;
    p.both = lo_ext && hi_ext;
    p.midpoint = p.both && (degree(lo) == 1) == (degree(hi) == 1);
    p.keep = !p.midpoint && (p.both ? degree(lo) == 1 : lo_ext) ? hi : lo;
    p.gone = p.keep == lo ? hi : lo;
    p.value = p.midpoint ? 0.5f * (critical_[idx(lo)].value + critical_[idx(hi)].value)
                         : critical_[idx(p.keep)].value;
    return p;
}

// Whether cancelling arc a would turn around an arc that has a parallel twin (one of two arcs
// joining the same two nodes: a loop of the graph, which no cancellation may close). The
// kept node's new value would leave the far end of both arcs on the other side, and
// flattening the cancelled nodes to that value would close the loop around the far node's
// value: the rewritten field would no longer agree with the graph (a noisy plate with two
// holes at area ratio 5 % rebuilt 66 critical nodes from a field whose graph had 9). Such a
// cancellation waits; the arc is looked at again when a cancellation changes its ends.
bool Simplifier::would_turn_a_loop(i32 a) const {
    const Pairing p = pairing(a);
    bool turns = false;
    // An arc of node n (other than a) ends at the kept node at p.value afterwards: it turns
    // when its far end is then on the other side of that value than the arc says.
    const auto check = [&](i32 n) {
        if (turns || (n == p.keep && !p.midpoint)) return;  // keep's arcs stay as they are
        if (big(n)) {
            turns = turns_a_loop_at_big(n, a, p.value);
            return;
        }
        for_each_arc(n, [&](i32 b) {
            if (turns || b == a) return;
            const auto& e = ends(b);
            const bool n_upper = e[1] == n;
            const float far = value(n_upper ? e[0] : e[1]);
            if ((n_upper ? far > p.value : far < p.value) && has_parallel_arc(b)) turns = true;
        });
    };
    check(p.gone);
    check(p.keep);
    return turns;
}

void Simplifier::cancel(i32 a, SimplifyResult& result) {
    turned_.clear();
    Arc& arc = arcs_[idx(a)];
    const auto [lo, hi] = ends(a);
    const Pairing p = pairing(a);
    const i32 keep = p.keep, gone = p.gone;
    const bool midpoint = p.midpoint, both = p.both;
    const double share_before = critical_[idx(keep)].area / static_cast<double>(degree(keep));
    const bool ext_before = extremum(keep);
    critical_[idx(keep)].value = p.value;
    ++(both ? result.extremum_extremum : result.saddle_extremum);
    CriticalNode& k = critical_[idx(keep)];
    k.flags |= kModified;
    unlink(a, lo);
    unlink(a, hi);
    --critical_[idx(hi)].down;
    absorb_list(arc, keep, false);
    arc.set = kNone;
    std::vector<i32>& touched = touched_;
    touched.clear();
    // keep_full: every arc of a big keep may have a new key or candidacy; keep_clear: they are
    // all looked at again (their waits end).
    bool keep_full = false, keep_clear = false;
    const bool handed_over = big(gone) && (!big(keep) || degree(gone) > degree(keep));
    if (handed_over) {
        hand_over(keep, gone, midpoint);  // (absorbs gone)
        keep_full = true;
    } else {
        // gone's arcs read before it is absorbed: its forward takes the slots they were in.
        arcs_at(gone, touched);
        critical_[idx(gone)].size = 0;
        release_run(critical_[idx(gone)]);
        critical_[idx(gone)].down = 0;
        absorb(gone, keep);
        for (const i32 b : touched) {
            const auto& e = ends(b);  // gone's ends now name keep
            link(b, keep);
            k.down += e[1] == keep;
        }
        if (midpoint) {
            arcs_at(keep, all_);
            for (const i32 b : all_) fit_arc(b, keep);
        } else {
            for (const i32 b : touched) fit_arc(b, keep);
        }
    }
    // keep's other arcs need a new look only if they may have become candidates: its
    // value moved, it became an extremum, or its area share per arc went down. Arcs that
    // stopped being candidates are dropped when they reach the top of the heap.
    const double share_after = degree(keep) == 0 ? 0.0 : k.area / static_cast<double>(degree(keep));
    if (midpoint || extremum(keep) != ext_before || share_after < share_before) {
        if (big(keep)) {
            keep_full = keep_clear = true;
            touched.clear();
        } else {
            arcs_at(keep, touched);
        }
    }

    merged_.clear();
    if (regularize(keep, merged_)) {
        touched.swap(merged_);
        ++result.made_regular;
    }
    result.arcs_turned += turned_.size();
    // An arc turned around moves one arc end at its far node from above to below or back:
    // that node may now be regular, or an extremum whose arcs are new candidates.
    for (const i32 n : turned_) {
        if (degree(n) == 0) continue;
        critical_[idx(n)].flags |= kModified;
        if (regularize(n, touched)) {
            ++result.made_regular;
            ++result.turned_made_regular;
        } else {
            result.turned_made_extremum += extremum(n);
            if (big(n)) {
                clear_waits(n);
                mark_full(n);
            } else {
                for_each_arc(n, [&](i32 b) { touched.push_back(b); });
            }
        }
    }
    promote_pending();
    for (const i32 b : touched) consider(b);
    if (big(keep)) {
        if (keep_clear) clear_waits(keep);
        if (keep_full)
            mark_full(keep);
        else
            rescan(keep);  // its candidate may have been the arc just cancelled
    }
    update_reps();
}

}  // namespace terrain::reeb::internal
