// Topological simplification of a Reeb graph (paper s.3.2, METHOD.md s.4).
//
// The rule. An arc is a candidate when
//   - one of its ends is an extremum (a minimum or a maximum),
//   - it is not one of several arcs between the same two nodes (those are the graph's loops,
//     which no threshold removes), and
//   - its persistence (how far apart its ends' values are) is below the persistence
//     threshold, or its area ratio (the area of its regular nodes plus each end's area shared
//     among that end's arcs, over the mesh's area) is below the area-ratio threshold; both
//     formulas are in arc_measures.hpp.
// Candidates are cancelled one at a time, lowest persistence first (ties by arc id), each on
// the graph the previous cancellations left (cancellation.cpp):
//   - saddle-extremum: the extremum and the arc are absorbed into the saddle;
//   - extremum-extremum: both ends become one node at the midpoint of their values.
// A cancellation changes values, degrees and areas around it, so the arcs there are looked at
// again: they may become candidates, or stop being ones. The simplification stops when no
// candidate is left. The vertices then take their node's value (simplify_output.cpp), so that
// the rewritten field and the simplified graph agree.
//
// How it is kept fast: the working graph is a copy laid out for few cache misses
// (working_graph.hpp); candidates wait in a queue (arc_queue.hpp) whose first keys are sorted
// once and read in order, later keys going to a 4-ary heap; an arc whose key changes or that
// stops being a candidate leaves its old entry behind, and a taken arc is checked again before
// it is cancelled. The loop waits on memory, so what it will touch next is fetched ahead.

#include "terrain/reeb/simplify.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>

#include <tbb/blocked_range.h>

#include "simplifier.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/release.hpp"

namespace terrain::reeb {

namespace internal {

void Simplifier::run(const ProgressFn& progress, SimplifyResult& result) {
    // Nodes with many arcs from the start (a pole's many-armed saddle) are big.
    promote_pending(true);
    // The candidates of the input graph, found on every thread: nothing is written but each
    // arc's own `queued` (its key's bits if it is a candidate, kWaits if it has a big end and
    // is not one; nothing is forwarded yet, so ends() writes nothing). Then, in arc order,
    // the candidates are queued and the others set waiting, as one pass in order did.
    constexpr std::uint32_t kWaits = kNotQueued - 1;  // (no persistence has these bits: a NaN)
    constexpr std::size_t kGrain = std::size_t{1} << 14;
    const std::size_t na = arcs_.size();
    detail::parallel_slices(na, kGrain, progress, kSeedStart, kCopyEnd, "simplify",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t a = r.begin(); a < r.end(); ++a) {
                                    if (a + kAhead < r.end()) prefetch_ends(a + kAhead);
                                    const i32 arc = static_cast<i32>(a);
                                    if (managed(arc)) {
                                        if (!candidate(arc)) arcs_[a].queued = kWaits;
                                        continue;
                                    }
                                    if (candidate(arc)) mark_queued(arc);
                                }
                            });
    for (std::size_t a = 0; a < na; ++a) {
        std::uint32_t& queued = arcs_[a].queued;
        if (queued == kNotQueued) continue;
        if (queued == kWaits) {
            queued = kNotQueued;
            set_waiting(static_cast<i32>(a));
            continue;
        }
        queue_.seed(std::uint64_t{queued} << 32 | static_cast<std::uint32_t>(a));
        ++pushed_;
    }
    queue_.seal();
    update_reps();
    std::size_t done = 0;
    // Progress on a clock: a noisy closed surface can spend minutes in cancellations of a
    // high-degree node, thousands of times slower than the first ones. Every 64 cancellations
    // the clock is read; at least every quarter second the fraction done of the work known
    // (cancellations made, plus the candidates queued) is reported, never going back.
    auto reported_at = std::chrono::steady_clock::now();
    double reported = kCopyEnd;  // the copy and the first candidates
    report_progress(progress, reported, "simplify");
    // Lowest persistence first, until no candidate is left.
    for (std::uint64_t key; (key = take()) != ArcQueue::kEmpty;) {
        const i32 a = ArcQueue::arc_of(key);
        prefetch_candidates_ahead();
        const std::uint64_t top = queue_.top();
        const std::size_t next = top == ArcQueue::kEmpty ? idx(a) : idx(ArcQueue::arc_of(top));
        __builtin_prefetch(&arcs_[next]);  // its ends are fetched once a is cancelled
        arcs_[idx(a)].queued = kNotQueued;
        popped(a);
        if (!candidate(a)) {  // no longer one since it was queued
            update_reps();
            continue;
        }
        const i32 b = redirect(a);
        if (would_turn_a_loop(b)) {  // it waits (cancellation.cpp)
            ++result.loop_waits;
            update_reps();
            continue;
        }
        cancel(b, result);
        if (check_steps_ && check_failure_.empty()) {  // (tests) the nodes just changed
            check_failure_ = check_big_nodes(done % 1024 == 0 ? nullptr : &updated_);
            if (!check_failure_.empty())
                check_failure_ =
                    "after cancellation " + std::to_string(done) + ": " + check_failure_;
            updated_.clear();
        }
        prefetch_ends(next);
        if ((++done & 63) == 0) {
            const auto now = std::chrono::steady_clock::now();
            if (now - reported_at >= std::chrono::milliseconds(250)) {
                reported_at = now;
                const double known = static_cast<double>(done + queue_.pending());
                reported = std::max(reported, kCopyEnd + (kOutputStart - kCopyEnd) *
                                                             static_cast<double>(done) / known);
                report_progress(progress, reported, "simplify");
            }
        }
    }
    if (check_steps_ && check_failure_.empty()) check_failure_ = check_big_nodes();
    result.working_bytes = working_bytes() + queue_.bytes();
    queue_.release();  // the output is the peak of memory: the queue is done
    detail::release(waiting_);
    report_progress(progress, kOutputStart, "simplify");
    write_result(result, options_.rewrite_field, scaled_progress(progress, kOutputStart, 1));
    report_progress(progress, 1.0, "simplify");
}

// The sorted entries ahead: their arcs (and heap slots) first, then (nearer) their ends.
void Simplifier::prefetch_candidates_ahead() const {
    const i32 far = queue_.sorted_ahead(kAhead), near = queue_.sorted_ahead(4);
    if (far != kNone) {
        __builtin_prefetch(&arcs_[idx(far)]);
        queue_.prefetch_slot(far);
    }
    if (near != kNone) prefetch_ends(idx(near));
}

}  // namespace internal

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
    internal::Simplifier(mesh, graph, options, internal::kBigDegree, progress)
        .run(progress, result);
    return result;
}

SimplifyResult simplify(const TriangleMesh& mesh, ReebGraph&& graph, const SimplifyOptions& options,
                        const ProgressFn& progress, Residency& memory) {
    check_simplify_options(options);
    if (graph.vertex_nodes.size() != mesh.vertex_count())
        throw Error("simplify", "the graph was not built on this mesh");
    SimplifyResult result;
    // The copy frees the graph's arrays as it reads them for the last time (the copy's end is
    // the peak of the simplification's memory); the output reads only the vertex lists and
    // links, and frees them too.
    internal::Simplifier simplifier(mesh, graph, options, internal::kBigDegree, progress, &graph,
                                    &memory);
    simplifier.own_input(graph);
    simplifier.run(progress, result);  // (which leaves the graph empty)
    return result;
}

}  // namespace terrain::reeb
