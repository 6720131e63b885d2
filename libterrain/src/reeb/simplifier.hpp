#pragma once
// Private: the simplification (paper s.3.2; the rule is told in simplify.cpp) as a class: the
// working graph (working_graph.hpp), the queue of candidates (arc_queue.hpp), and the
// cancellation rules (cancellation.cpp).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "arc_queue.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/reeb/simplify.hpp"
#include "working_graph.hpp"

namespace terrain::reeb::internal {

class Simplifier : WorkingGraph {
  public:
    Simplifier(const TriangleMesh& mesh, const ReebGraph& g, const SimplifyOptions& options)
        : WorkingGraph(mesh, g), options_(options) {
        queue_.init(arcs_.size());
    }

    // Cancels candidates until none is left, then writes the result (simplify.cpp).
    void run(const ProgressFn& progress, SimplifyResult& result);

  private:
    // The rule's candidate (simplify.cpp): a live arc with an extremum end, no parallel twin,
    // and a persistence or an area ratio below its threshold.
    bool candidate(i32 a) const {
        const Arc& arc = arcs_[idx(a)];
        if (arc.set == kNone) return false;
        if (!extremum(arc.end[0]) && !extremum(arc.end[1])) return false;
        if (has_parallel_arc(a)) return false;
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
        const std::uint64_t key = ArcQueue::key_of(persistence(a), a);
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
        for (const i32 e : arcs_[a].end) __builtin_prefetch(&critical_[idx(e)]);
    }

    SimplifyOptions options_;
    ArcQueue queue_;
    std::size_t pushed_ = 0;
    std::vector<i32> touched_, all_, merged_;
    std::vector<i32> turned_;  // far ends of the arcs fit_arc turned around
};

}  // namespace terrain::reeb::internal
