// The flooding of segment::divide_absorbed, in order or in parts on the threads (flooding.hpp).

#include "flooding.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <limits>
#include <thread>

#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/radix_heap.hpp"
#include "terrain/internal/mesh/prefetch_around.hpp"

namespace terrain::segment::internal {

using detail::i32;
using detail::idx;

double edge_length(const TriangleMesh& mesh, std::size_t a, std::size_t b) {
    const auto& p = mesh.positions()[a];
    const auto& q = mesh.positions()[b];
    return std::sqrt(double(p[0] - q[0]) * (p[0] - q[0]) + double(p[1] - q[1]) * (p[1] - q[1]) +
                     double(p[2] - q[2]) * (p[2] - q[2]));
}

double mean_edge_length(const TriangleMesh& mesh, const ProgressFn& progress, double from,
                        double to) {
    const detail::PassProgress pass(progress, from, to, "divide");
    const std::size_t n = mesh.vertex_count();
    constexpr std::size_t kBlockShift = 12;
    const std::size_t blocks = (n >> kBlockShift) + 1;
    constexpr std::size_t kWaveBlocks = 64;  // (a wave's lengths: 2^18 vertices, about 12 MB)
    std::array<std::vector<double>, kWaveBlocks> lengths;
    double sum = 0;
    std::size_t count = 0;
    for (std::size_t b0 = 0; b0 < blocks; b0 += kWaveBlocks) {
        pass.at(b0 << kBlockShift, n);
        const std::size_t b1 = std::min(blocks, b0 + kWaveBlocks);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(b0, b1, 1),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t b = r.begin(); b < r.end(); ++b) {
                                  std::vector<double>& mine = lengths[b - b0];
                                  mine.clear();
                                  const std::size_t last = std::min(n, (b + 1) << kBlockShift);
                                  for (std::size_t v = b << kBlockShift; v < last; ++v)
                                      for (const i32 w : mesh.neighbors_of(v))
                                          mine.push_back(edge_length(mesh, v, idx(w)));
                              }
                          });
        for (std::size_t b = b0; b < b1; ++b) {
            for (const double len : lengths[b - b0]) sum += len;
            count += lengths[b - b0].size();
        }
    }
    return count == 0 || sum <= 0 ? 1.0 : sum / double(count);
}

void Flooding::prefetch(std::size_t vertex) const {
    detail::prefetch_around(mesh_, vertex, sites_, field_, mesh_.positions());
}

namespace {

// Reports the share of the vertices labelled, every 2^16 of them.
void report_labelled(const ProgressFn& progress, std::size_t before, std::size_t labelled,
                     std::size_t to_label) {
    if ((labelled >> 16) == (before >> 16)) return;
    const double share = double(labelled) / double(std::max<std::size_t>(1, to_label));
    report_progress(progress, 0.05 + 0.95 * std::min(1.0, share), "divide");
}

}  // namespace

void flood_in_order(const Flooding& flooding, std::size_t to_label, const ProgressFn& progress) {
    std::vector<Site>& sites = flooding.sites();
    const TriangleMesh& mesh = flooding.mesh();
    const std::size_t n = sites.size();
    // (A path's cost never falls below the cost of the vertex it leaves, so the offers wait in
    // a monotone queue: core/radix_heap.hpp.)
    detail::RadixHeap<Step> heap;
    // Offers from w (in a region) to the vertices around it without one, when better than
    // their best so far (the same result as queuing every one: costs grow along a path, so a
    // vertex's first offer taken is its cheapest).
    const auto offer_around = [&](std::size_t w) {
        const Site at = sites[w];
        for (const i32 nw : mesh.neighbors_of(w)) {
            const std::size_t u = idx(nw);
            if (is_final(sites[u])) continue;
            const float c = flooding.offer(w, at, u);
            const Site offer = site_of(c, region_of(at));
            if (offer >= sites[u]) continue;
            sites[u] = offer;
            heap.push(Step{c, static_cast<i32>(u), region_of(at)});
        }
    };
    const detail::PassProgress fronts(progress, 0, 0.05, "divide");
    for (std::size_t w = 0; w < n; ++w)
        if (fronts.at(w, n); is_final(sites[w])) offer_around(w);
    report_progress(progress, 0.05, "divide");
    std::size_t labelled = 0;
    while (!heap.empty()) {
        const Step s = heap.pop();
        // (The next offer's memory is asked for while this one is taken: popped in cost
        // order, the vertices are scattered over the surface.)
        if (const Step* next = heap.peek()) flooding.prefetch(idx(next->vertex));
        Site& site = sites[idx(s.vertex)];
        if (site != site_of(s.cost, s.label)) continue;  // a better offer came
        site |= kFinal;
        offer_around(idx(s.vertex));
        report_labelled(progress, labelled, labelled + 1, to_label);
        ++labelled;
    }
}

namespace {

// The parts' state in flood_in_parts: each part's queue and, by the part that made them, the
// offers to its vertices from other parts, handed over between rounds.
struct Parts {
    std::size_t size = 1, count = 1;  // part p: vertices [p size, (p + 1) size)
    std::vector<detail::RadixHeap<Step>> heaps;
    std::vector<std::vector<Step>> inbox;  // [to * count + from]
    // least[from * count + to]: the least step over an edge from part `from` to part `to`
    // (+infinity: no edge).
    std::vector<float> least;
    std::size_t part_of(std::size_t v) const { return v / size; }
};

// Sites are read and written by several threads: every access is atomic (relaxed: a stale
// read only makes an offer that is dropped later).
Site load(std::vector<Site>& sites, std::size_t v) {
    return std::atomic_ref<Site>(sites[v]).load(std::memory_order_relaxed);
}
void store(std::vector<Site>& sites, std::size_t v, Site s) {
    std::atomic_ref<Site>(sites[v]).store(s, std::memory_order_relaxed);
}

// Offers from w (at `at`, in part p) to the vertices around it without a final region: to
// p's own queue, or to the other part's inbox.
void offer_around(const Flooding& flooding, Parts& parts, std::size_t p, std::size_t w, Site at) {
    std::vector<Site>& sites = flooding.sites();
    for (const i32 nw : flooding.mesh().neighbors_of(w)) {
        const std::size_t u = idx(nw);
        const Site current = load(sites, u);
        if (is_final(current)) continue;
        const float c = flooding.offer(w, at, u);
        const Site offer = site_of(c, region_of(at));
        if (offer >= current) continue;
        const std::size_t q = parts.part_of(u);
        const Step step{c, static_cast<i32>(u), region_of(at)};
        if (q == p) {
            store(sites, u, offer);
            parts.heaps[p].push(step);
        } else {
            parts.inbox[q * parts.count + p].push_back(step);
        }
    }
}

// The least steps between parts, and the first offers: each part's final vertices offer to
// their neighbours.
void start_parts(const Flooding& flooding, Parts& parts) {
    const std::size_t n = flooding.sites().size(), k = parts.count;
    parts.least.assign(k * k, std::numeric_limits<float>::infinity());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, k, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t p = r.begin(); p < r.end(); ++p) {
                              const std::size_t last = std::min(n, (p + 1) * parts.size);
                              float* least = &parts.least[p * k];
                              for (std::size_t w = p * parts.size; w < last; ++w) {
                                  for (const i32 nu : flooding.mesh().neighbors_of(w)) {
                                      const std::size_t q = parts.part_of(idx(nu));
                                      if (q != p)
                                          least[q] = std::min(least[q], flooding.step(idx(nu), w));
                                  }
                                  const Site at = load(flooding.sites(), w);
                                  if (is_final(at)) offer_around(flooding, parts, p, w, at);
                              }
                          }
                      });
}

// The offers handed to each part from the others, into its queue where they are better than
// its vertices' best so far.
void hand_over(const Flooding& flooding, Parts& parts) {
    const std::size_t k = parts.count;
    std::vector<Site>& sites = flooding.sites();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, k, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t q = r.begin(); q < r.end(); ++q)
                              for (std::size_t p = 0; p < k; ++p) {
                                  auto& box = parts.inbox[q * k + p];
                                  for (const Step& s : box) {
                                      const std::size_t u = idx(s.vertex);
                                      const Site current = load(sites, u);
                                      const Site offer = site_of(s.cost, s.label);
                                      if (is_final(current) || offer >= current) continue;
                                      store(sites, u, offer);
                                      parts.heaps[q].push(s);
                                  }
                                  box.clear();
                              }
                      });
}

// Takes part p's offers below `bound` in order; returns how many it labelled.
std::size_t take_below(const Flooding& flooding, Parts& parts, std::size_t p, float bound,
                       std::size_t most = std::numeric_limits<std::size_t>::max()) {
    std::vector<Site>& sites = flooding.sites();
    auto& heap = parts.heaps[p];
    std::size_t labelled = 0;
    while (labelled < most) {
        const Step* top = heap.peek();
        if (!top || !(top->cost < bound)) break;
        const Step s = heap.pop();
        if (const Step* next = heap.peek()) flooding.prefetch(idx(next->vertex));
        const Site at = site_of(s.cost, s.label);
        if (load(sites, idx(s.vertex)) != at) continue;  // a better offer came
        store(sites, idx(s.vertex), at | kFinal);
        offer_around(flooding, parts, p, idx(s.vertex), at | kFinal);
        ++labelled;
    }
    return labelled;
}

// What each part may take in a round: its offers below the least offer another part can still
// make to it. `waiting`: each part's cheapest waiting offer (+infinity: none). A part's
// offers to come cost at least the least of its own waiting offer and, through each
// neighbouring part, that part's least offer to come plus the least step between the two (a
// shortest path over the parts, in the floats the offers are summed in); a part's bound is
// the least over its neighbours of that plus the step to it.
void parts_bounds(const Parts& parts, const std::vector<float>& waiting,
                  std::vector<float>& bound) {
    const std::size_t k = parts.count;
    constexpr float kNever = std::numeric_limits<float>::infinity();
    std::vector<float> least_to_come = waiting;
    std::vector<char> done(k, 0);
    for (std::size_t round = 0; round < k; ++round) {
        std::size_t p = k;
        for (std::size_t q = 0; q < k; ++q)
            if (!done[q] && least_to_come[q] != kNever &&
                (p == k || least_to_come[q] < least_to_come[p]))
                p = q;
        if (p == k) break;
        done[p] = 1;
        for (std::size_t q = 0; q < k; ++q)
            if (!done[q] && parts.least[p * k + q] != kNever)
                least_to_come[q] =
                    std::min(least_to_come[q], least_to_come[p] + parts.least[p * k + q]);
    }
    for (std::size_t q = 0; q < k; ++q) {
        bound[q] = kNever;
        for (std::size_t p = 0; p < k; ++p)
            if (p != q && least_to_come[p] != kNever && parts.least[p * k + q] != kNever)
                bound[q] = std::min(bound[q], least_to_come[p] + parts.least[p * k + q]);
    }
}

}  // namespace

void flood_in_parts(const Flooding& flooding, std::size_t part_count, std::size_t to_label,
                    const ProgressFn& progress) {
    const std::size_t n = flooding.sites().size();
    Parts parts;
    const std::size_t asked = std::max<std::size_t>(1, part_count);
    parts.size = std::max<std::size_t>(1, (n + asked - 1) / asked);
    const std::size_t k = parts.count = std::max<std::size_t>(1, (n + parts.size - 1) / parts.size);
    parts.heaps.resize(k);
    parts.inbox.resize(k * k);
    start_parts(flooding, parts);
    report_progress(progress, 0.05, "divide");
    constexpr float kNever = std::numeric_limits<float>::infinity();
    std::vector<float> waiting(k), bound(k);
    std::vector<std::size_t> taken(k);
    std::size_t labelled = 0;
    for (;;) {
        hand_over(flooding, parts);
        // Each part's cheapest waiting offer, and what it may take: below the least offer a
        // neighbouring part can still make.
        for (std::size_t p = 0; p < k; ++p) {
            const Step* top = parts.heaps[p].peek();
            waiting[p] = top ? top->cost : kNever;
        }
        if (std::all_of(waiting.begin(), waiting.end(), [](float w) { return w == kNever; })) break;
        parts_bounds(parts, waiting, bound);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, k, 1),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t p = r.begin(); p < r.end(); ++p)
                                  taken[p] = take_below(flooding, parts, p, bound[p]);
                          });
        std::size_t round = 0;
        for (const std::size_t t : taken) round += t;
        if (round == 0) {
            // No part could take anything (a step that rounds away to nothing at these costs):
            // the least offer of all is final, as flood_in_order takes it next.
            std::size_t first = k;
            for (std::size_t p = 0; p < k; ++p)
                if (const Step* top = parts.heaps[p].peek();
                    top && (first == k || top->key() < parts.heaps[first].peek()->key()))
                    first = p;
            if (first == k) continue;  // (only offers made stale were left)
            round = take_below(flooding, parts, first, kNever, 1);
        }
        report_labelled(progress, labelled, labelled + round, to_label);
        labelled += round;
    }
}

}  // namespace terrain::segment::internal
