// The candidates of big nodes (simplifier.hpp, working_graph.hpp): nodes with many arcs
// queue one arc each, their candidate with the smallest key, found in their ordered sets.
// The rule is the one simplify.cpp tells; only where it is looked up changes. A big node's
// candidate is the arc with the smallest (persistence, arc id) among its arcs that are
// candidates and not waiting, read nearest first from its `far` set (or, for a node that
// is not an extremum, from its `ext` set: only arcs to an extremum can be candidates there).

#include <algorithm>
#include <string>

#include "simplifier.hpp"

namespace terrain::reeb::internal {

void Simplifier::promote_pending(bool initial) {
    for (std::size_t i = 0; i < pending_big_.size(); ++i) {
        const i32 n = pending_big_[i];
        CriticalNode& c = critical_[idx(n)];
        if (!(c.flags & kPending)) continue;
        c.flags = static_cast<std::uint8_t>(c.flags & ~kPending);
        if (forward(n) != kNone || !(c.flags & kCritical) || i32(c.size) < big_degree_) continue;
        make_big(n);
        BigNode& b = big_of(n);
        for (const auto& [arc, keys] : b.keys) {
            (void)keys;
            // An arc that was queued on its own is now queued through n (and through its other
            // end if that is big already, in which case nothing changes for it).
            if (!initial && !big(other_end(arc, n))) queue_through_big_end(arc);
        }
        // (its waiting list in arc order, for the same result whatever the hash)
        std::vector<i32> waits;
        for (const auto& entry : b.keys)
            if (waiting_[idx(entry.first)]) waits.push_back(entry.first);
        std::sort(waits.begin(), waits.end());
        b.waiting = std::move(waits);
        rescan(n);
    }
    pending_big_.clear();
}

// Arc b, queued on its own until now, is queued through its new big end: its own entry goes,
// and being out of the queue becomes its waiting flag.
void Simplifier::queue_through_big_end(i32 b) {
    const bool queued = arcs_[idx(b)].queued != kNotQueued;
    if (queued) {
        queue_.erase(b);
        arcs_[idx(b)].queued = kNotQueued;
    }
    waiting_[idx(b)] = !queued;
}

void Simplifier::mark_dirty(i32 n) {
    CriticalNode& c = critical_[idx(n)];
    if (c.flags & kDirty) return;
    c.flags |= kDirty;
    dirty_big_.push_back(n);
}

void Simplifier::mark_changed(i32 n, i32 b) {
    big_of(n).changed.push_back(b);
    mark_dirty(n);
}

void Simplifier::rescan(i32 n) {
    big_of(n).full = true;
    mark_dirty(n);
}

// n's value, area share or status changed: its candidate is looked for anew, and so are the
// candidates of the big nodes at the other end of its arcs, whose keys and candidacy depend
// on n.
void Simplifier::mark_full(i32 n) {
    rescan(n);
    BigNode& b = big_of(n);
    for (auto it = b.bb.begin(); it != b.bb.end();) {
        const i32 arc = *it;
        const i32 m = arcs_[idx(arc)].set == kNone ? kNone : other_end(arc, n);
        if (m == kNone || m == n || !big(m) || !b.keys.count(arc)) {
            it = b.bb.erase(it);
            continue;
        }
        refresh(m, arc);
        mark_changed(m, arc);
        ++it;
    }
}

void Simplifier::clear_waits(i32 n) {
    BigNode& b = big_of(n);
    for (const i32 w : b.waiting)
        if (b.keys.count(w)) waiting_[idx(w)] = false;
    b.waiting.clear();
}

void Simplifier::set_waiting(i32 b) {
    waiting_[idx(b)] = true;
    const auto e = ends(b);
    for (int i = 0; i < 2; ++i)
        if (big(e[i]) && (i == 0 || e[1] != e[0])) big_of(e[i]).waiting.push_back(b);
}

void Simplifier::consider_managed(i32 a) {
    waiting_[idx(a)] = false;
    const auto e = ends(a);
    bool rep = false;
    for (const i32 n : e)
        if (big(n) && big_of(n).rep == a) rep = true;
    // An entry of its own, from before it had a big end, is dropped.
    if (!rep && arcs_[idx(a)].queued != kNotQueued) {
        queue_.erase(a);
        arcs_[idx(a)].queued = kNotQueued;
    }
    for (int i = 0; i < 2; ++i) {
        if (!big(e[i]) || (i == 1 && e[1] == e[0])) continue;
        refresh(e[i], a);
        mark_changed(e[i], a);
    }
}

void Simplifier::popped(i32 a) {
    if (arcs_[idx(a)].set == kNone || !managed(a)) return;
    set_waiting(a);
    for (const i32 n : ends(a))
        if (big(n) && big_of(n).rep == a) rescan(n);
}

i32 Simplifier::best_candidate(i32 n) const {
    const BigNode& b = big_of(n);
    const auto& sets = extremum(n) ? b.far : b.ext;
    auto it0 = sets[0].begin(), it1 = sets[1].begin();
    const auto end0 = sets[0].end(), end1 = sets[1].end();
    for (;;) {
        const bool has0 = it0 != end0, has1 = it1 != end1;
        if (!has0 && !has1) return kNone;
        const float p0 = has0 ? persistence(it0->second) : 0,
                    p1 = has1 ? persistence(it1->second) : 0;
        const float p = !has1 ? p0 : !has0 ? p1 : std::min(p0, p1);
        // Every arc at this persistence, on both sides: the candidate with the smallest id.
        i32 best = kNone;
        const auto gather = [&](auto& it, const auto& end) {
            for (; it != end && persistence(it->second) == p; ++it) {
                const i32 arc = it->second;
                if ((best == kNone || arc < best) && !waiting_[idx(arc)] && candidate(arc))
                    best = arc;
            }
        };
        gather(it0, end0);
        gather(it1, end1);
        if (best != kNone) return best;
    }
}

void Simplifier::set_rep(i32 n, i32 r) {
    BigNode& b = big_of(n);
    const i32 old = b.rep;
    b.rep = r;
    if (old != r && old != kNone && arcs_[idx(old)].queued != kNotQueued) {
        // Dropped from the queue unless it is its other end's candidate too.
        const i32 m = arcs_[idx(old)].set == kNone ? kNone : other_end(old, n);
        if (m == kNone || !big(m) || big_of(m).rep != old) {
            queue_.erase(old);
            arcs_[idx(old)].queued = kNotQueued;
        }
    }
    if (r == kNone) return;
    const std::uint64_t k = mark_queued(r);
    if (k == ArcQueue::kEmpty) return;
    queue_.set(k);
    ++pushed_;
}

void Simplifier::update_reps() {
    if (check_steps_) updated_.insert(updated_.end(), dirty_big_.begin(), dirty_big_.end());
    for (const i32 n : dirty_big_) {
        CriticalNode& c = critical_[idx(n)];
        c.flags = static_cast<std::uint8_t>(c.flags & ~kDirty);
        if (!(c.flags & kBig) || forward(n) != kNone) continue;  // gone, or made regular
        BigNode& b = big_of(n);
        const i32 r = b.rep;
        bool full = b.full;
        if (!full && r != kNone) {
            full = arcs_[idx(r)].set == kNone || !b.keys.count(r) ||
                   arcs_[idx(r)].queued != key(r) >> 32 ||
                   std::find(b.changed.begin(), b.changed.end(), r) != b.changed.end();
        }
        i32 best;
        if (full) {
            best = best_candidate(n);
        } else {
            best = r;
            for (const i32 a : b.changed) {
                if (a == best || arcs_[idx(a)].set == kNone || !b.keys.count(a) ||
                    waiting_[idx(a)] || !candidate(a))
                    continue;
                if (best == kNone || key(a) < key(best)) best = a;
            }
        }
        b.changed.clear();
        b.full = false;
        set_rep(n, best);
    }
    dirty_big_.clear();
}

// redirect() at a big extremum: its arcs nearest first, the first (smallest id among equal
// persistence) whose far end is no extremum and that has no parallel twin, if it is nearer
// than candidate a.
i32 Simplifier::redirect_big(i32 a, i32 ext) const {
    const int side = down(ext) == 0 ? 1 : 0;
    i32 best = kNone;
    float best_gap = persistence(a);
    for (const auto& entry : big_of(ext).far[side]) {
        const i32 b = entry.second;
        const float gap = persistence(b);
        if (best == kNone ? gap >= best_gap : gap > best_gap) break;
        if (b == a || extremum(other_end(b, ext)) || has_parallel_arc(b)) continue;
        if (best == kNone || b < best) {
            best = b;
            best_gap = gap;
        }
    }
    return best == kNone ? a : best;
}

// would_turn_a_loop() at a big node n taking `value`: its arcs whose far end would be on the
// other side, looked up.
bool Simplifier::turns_a_loop_at_big(i32 n, i32 a, float value) const {
    const BigNode& b = big_of(n);
    for (const auto& [k, arc] : b.far[0]) {
        if (-k <= value) break;
        if (arc != a && has_parallel_arc(arc)) return true;
    }
    for (const auto& [k, arc] : b.far[1]) {
        if (k >= value) break;
        if (arc != a && has_parallel_arc(arc)) return true;
    }
    return false;
}

void Simplifier::hand_over(i32 keep, i32 gone, bool midpoint) {
    CriticalNode& k = critical_[idx(keep)];
    CriticalNode& g = critical_[idx(gone)];
    // keep's own arcs step out, gone's set becomes keep's, keep's arcs join it.
    arcs_at(keep, own_);
    std::reverse(own_.begin(), own_.end());  // oldest first, as they were linked
    const i32 keep_down = k.down;
    const bool keep_was_big = (k.flags & kBig) != 0;
    release_run(k);
    k.size = g.size;
    k.down = keep_down + g.down;
    k.slot[0] = g.slot[0];
    k.flags = static_cast<std::uint8_t>((k.flags | kBig) & ~kPending);
    g.flags = static_cast<std::uint8_t>(g.flags & ~(kBig | kPending));
    g.size = 0;
    g.down = 0;
    absorb(gone, keep);  // (its forward takes the slot its set was in)
    clear_waits(keep);   // gone's arcs are all looked at again, as cancel() does for moved arcs
    for (const i32 b : own_) {
        const i32 other = other_end(b, keep);
        link(b, keep);
        if (!keep_was_big && !big(other)) queue_through_big_end(b);
        if (waiting_[idx(b)]) big_of(keep).waiting.push_back(b);
    }
    // The arcs to fit: all of them at a midpoint, else those whose nearest value is now on
    // the wrong side of keep's (keep's own arcs are fitted to it already).
    fit_.clear();
    if (midpoint) {
        arcs_at(keep, fit_);
    } else {
        const float fk = k.value;
        const BigNode& b = big_of(keep);
        for (const auto& [key_value, arc] : b.near[0]) {
            if (-key_value <= fk) break;
            fit_.push_back(arc);
        }
        for (const auto& [key_value, arc] : b.near[1]) {
            if (key_value >= fk) break;
            fit_.push_back(arc);
        }
    }
    for (const i32 b : fit_) fit_arc(b, keep);
}

std::string Simplifier::check_big_nodes(const std::vector<i32>* only) const {
    const auto at = [](const char* what, i32 n, i32 a) {
        return std::string(what) + " (node " + std::to_string(n) + ", arc " + std::to_string(a) +
               ")";
    };
    const std::size_t count = only ? only->size() : idx(critical_count_);
    for (std::size_t i = 0; i < count; ++i) {
        const i32 n = only ? (*only)[i] : static_cast<i32>(i);
        const CriticalNode& c = critical_[idx(n)];
        if (!(c.flags & kBig)) continue;
        if (forward(n) != kNone) return at("a big node was absorbed but kept its set", n, kNone);
        const BigNode& b = big_of(n);
        if (static_cast<i32>(b.keys.size()) != c.size) return at("degree", n, kNone);
        i32 below = 0;
        for (const auto& [arc, k] : b.keys) {
            if (arcs_[idx(arc)].set == kNone) return at("a gone arc in a set", n, arc);
            const auto& e = ends(arc);
            if (e[0] != n && e[1] != n)
                return at("an arc in the set of a node it does not end at", n, arc);
            below += e[1] == n;
            if (!(keys_of(arc, n) == k)) return at("stale keys", n, arc);
        }
        if (below != c.down) return at("arcs below", n, kNone);
        // A node just updated has no candidate before its queued one. (Its queued one may
        // have stopped being a candidate, as an arc queued on its own may: it is dropped when
        // it is taken. A node not looked at since may hold arcs whose candidacy changed
        // silently, as the queue of single arcs may.)
        if (only) {
            const i32 best = best_candidate(n);
            if (best != kNone && (b.rep == kNone || key(best) < key(b.rep)))
                return at("a candidate before the queued one", n, best);
        }
        if (b.rep != kNone && arcs_[idx(b.rep)].queued != key(b.rep) >> 32)
            return at("candidate not queued with its key", n, b.rep);
    }
    return {};
}

}  // namespace terrain::reeb::internal
