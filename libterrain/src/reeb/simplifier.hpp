#pragma once
// Private: the simplification (paper s.3.2; the rule is told in simplify.cpp) as a class: the
// working graph (working_graph.hpp), the queue of candidates (arc_queue.hpp), the
// cancellation rules (cancellation.cpp) and the candidates of big nodes (big_nodes.cpp).
//
// An arc with a big end is not queued on its own: each big node queues one arc, its
// candidate with the smallest key (its `rep`), found in its ordered sets; when anything at
// the node changes the node is marked (changed arcs, or `full` when its value, share or
// status changed) and its candidate is chosen again after the cancellation
// (update_reps()). What the queue of single arcs says by an arc's absence (not queued: it
// waited, was dropped, or was never a candidate since it was last looked at) such an arc
// says with its `waiting` flag, cleared wherever an arc would be looked at again.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "arc_queue.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/reeb/simplify.hpp"
#include "working_graph.hpp"

namespace terrain::reeb::internal {

class Simplifier : WorkingGraph {
  public:
    // The copy into the working graph reports through `progress` as 0 to 1 of the whole
    // simplification's first quarter (run() reports the rest).
    // `owned`, `memory`, `wave`: see WorkingGraph.
    Simplifier(const TriangleMesh& mesh, const ReebGraph& g, const SimplifyOptions& options,
               i32 big_degree = kBigDegree, const ProgressFn& progress = {},
               ReebGraph* owned = nullptr, Residency* memory = nullptr,
               std::size_t wave = kCopyWave)
        : WorkingGraph(mesh, g, big_degree, scaled_progress(progress, 0, kSeedStart), owned, memory,
                       wave),
          options_(options) {
        queue_.init(arcs_.size());
        waiting_.assign(arcs_.size(), false);
    }

    // Slices of the simplification's progress, by their measured cost on global grids: the
    // copy into the working graph, the cancellations, the output.
    // The candidates are queued from kSeedStart to kCopyEnd.
    static constexpr double kSeedStart = 0.2, kCopyEnd = 0.25, kOutputStart = 0.75;

    using WorkingGraph::own_input;

    // Cancels candidates until none is left, then writes the result (simplify.cpp).
    void run(const ProgressFn& progress, SimplifyResult& result);

    // Tests: check the big nodes after every cancellation (slow); the first problem found,
    // with the cancellation's number, is kept in check_failure().
    void check_each_step() { check_steps_ = true; }
    const std::string& check_failure() const { return check_failure_; }
    // Arcs moved from a node to another (linked anew) so far: what cancellations cost.
    std::size_t arcs_moved() const { return moves_; }

  private:
    // The rule's candidate (simplify.cpp): a live arc with an extremum end, no parallel twin,
    // and a persistence or an area ratio below its threshold.
    bool candidate(i32 a) const {
        const Arc& arc = arcs_[idx(a)];
        if (arc.set == kNone) return false;
        const auto& e = ends(a);
        if (!extremum(e[0]) && !extremum(e[1])) return false;
        if (has_parallel_arc(a)) return false;
        return persistence(a) < options_.persistence || area_ratio(a) < options_.area_ratio / 100.0;
    }
    // Queues arc a with its current key if it is a candidate, else takes it out of the
    // queue. An arc with a big end is looked at again through that end (big_nodes.cpp).
    void consider(i32 a) {
        if (arcs_[idx(a)].set != kNone && managed(a)) {
            consider_managed(a);
            return;
        }
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
        const std::uint64_t key = ArcQueue::key_of(persistence(a), a);
        std::uint32_t& queued = arcs_[idx(a)].queued;
        if (queued == key >> 32) return ArcQueue::kEmpty;
        queued = static_cast<std::uint32_t>(key >> 32);
        return key;
    }
    // The smallest current key queued, taken out (entries left behind are dropped on the way);
    // kEmpty when none is left. A sorted entry stands while its arc is queued outside the
    // heap, with the key it was seeded with (every key set later goes to the heap).
    std::uint64_t take() {
        const auto current = [&](std::uint64_t key) {
            return arcs_[key & 0xffffffffu].queued == key >> 32;
        };
        for (;;) {
            i32 a = queue_.sorted_front();
            while (a != kNone && (arcs_[idx(a)].queued == kNotQueued || queue_.in_heap(a))) {
                queue_.skip_sorted();
                a = queue_.sorted_front();
            }
            const std::uint64_t s = a == kNone ? ArcQueue::kEmpty
                                               : std::uint64_t{arcs_[idx(a)].queued} << 32 |
                                                     static_cast<std::uint32_t>(a);
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

    // Big nodes (big_nodes.cpp).
    void promote_pending(bool initial = false);  // nodes flagged kPending become big
    void consider_managed(i32 a);                // consider() for an arc with a big end
    void queue_through_big_end(i32 b);           // arc b just got its first big end
    void mark_changed(i32 n, i32 b);             // arc b at big node n changed
    void mark_full(i32 n);                       // everything at big node n may have changed
    void rescan(i32 n);                          // big node n's candidate is looked for anew
    void mark_dirty(i32 n);
    void clear_waits(i32 n);  // all of big node n's arcs are looked at again
    void set_waiting(i32 b);  // arc b (with a big end) is out of the queue
    void popped(i32 a);       // arc a left the queue through take()
    void update_reps();       // the marked big nodes' candidates chosen again
    // The first inconsistency of the big nodes' sets and candidates, empty if none (tests).
    // `only`: these nodes (those that changed), else all.
    std::string check_big_nodes(const std::vector<i32>* only = nullptr) const;
    i32 best_candidate(i32 n) const;  // big node n's candidate with the smallest key
    void set_rep(i32 n, i32 r);
    std::uint64_t key(i32 b) const { return ArcQueue::key_of(persistence(b), b); }
    i32 redirect_big(i32 a, i32 ext) const;
    bool turns_a_loop_at_big(i32 n, i32 a, float value) const;
    // cancel() when the gone node is big and has more arcs than the kept one: its set is
    // handed over and only the arcs that need it are fitted.
    void hand_over(i32 keep, i32 gone, bool midpoint);

    // The cancellation rules (cancellation.cpp).
    i32 redirect(i32 a) const;
    struct Pairing {
        i32 keep = kNone, gone = kNone;
        bool midpoint = false;  // two extrema meeting at the midpoint of their values
        bool both = false;      // two extrema
        float value = 0;        // keep's value afterwards
    };
    Pairing pairing(i32 a) const;
    bool would_turn_a_loop(i32 a) const;
    void cancel(i32 a, SimplifyResult& result);
    void fit_arc(i32 b, i32 keep);
    bool regularize(i32 n, std::vector<i32>& out);

    // Memory that the main loop will touch soon, fetched early (simplify.cpp).
    void prefetch_candidates_ahead() const;
    void prefetch_ends(std::size_t a) const {
        for (const i32 e : arcs_[a].end) __builtin_prefetch(&critical_[idx(e)]);  // (maybe stale)
    }

    SimplifyOptions options_;
    ArcQueue queue_;
    std::size_t pushed_ = 0;
    std::vector<i32> touched_, all_, merged_;
    std::vector<i32> turned_;     // far ends of the arcs fit_arc turned around
    std::vector<bool> waiting_;   // per arc with a big end: out of the queue (a bit an arc)
    std::vector<i32> dirty_big_;  // big nodes flagged kDirty
    std::vector<i32> own_, fit_;  // hand_over()'s scratch
    bool check_steps_ = false;
    std::vector<i32> updated_;  // with check_steps_: the big nodes update_reps() looked at
    std::string check_failure_;
};

}  // namespace terrain::reeb::internal
