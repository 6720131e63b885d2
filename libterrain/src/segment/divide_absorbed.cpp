

// Absorbed vertices divided among the regions around them (divide_absorbed.hpp).
//
// 1. Absorbed vertices leave their regions.
// 2. Each region keeps the part connected to its seed (the seed node's own vertices, never
//    absorbed) through its remaining vertices; the rest of it leaves too (a region may have
//    reached those parts through the absorbed vertices only).
// 3. The vertices without a region join one by a flooding over the mesh's edges from the
//    regions' edges, cheapest path first: a path into region r costs, at each vertex u it
//    crosses, |field(u) - mean(r)| (r's mean over the vertices it kept) plus a constant per
//    edge length. A region thus takes the absorbed vertices that resemble it and are near it;
//    the constant keeps paths through noise from crossing the body before each region took
//    its surroundings.

#include "terrain/segment/divide_absorbed.hpp"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "divide_absorbed_internal.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/indices.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/radix_heap.hpp"
#include "terrain/internal/mesh/prefetch_around.hpp"

namespace terrain::segment {

namespace {

using detail::i32;
using detail::idx;

// An offer of `label` to `vertex` at path cost `cost`. Taken in order of (cost, vertex): costs
// are never negative, so their bits order as the costs do. Offers of equal cost and vertex
// differ by label; only the latest (the lowest label) is still the vertex's offer when taken,
// so their order does not matter.
struct Step {
    float cost;
    i32 vertex;
    std::uint32_t label;
    std::uint64_t key() const {
        return std::uint64_t{std::bit_cast<std::uint32_t>(cost)} << 32 |
               static_cast<std::uint32_t>(vertex);
    }
};

// The cost of one mean edge length, as a share of the field's spread: without it, paths
// through noise of small steps would cross the body before any region took its surroundings.
constexpr float kStepShare = 0.01f;

// The field's range over the vertices that keep their region (1 when flat).
float field_spread(const std::vector<float>& field) {
    if (field.empty()) return 1.0f;
    const auto [lo, hi] = std::minmax_element(field.begin(), field.end());
    return *hi > *lo ? *hi - *lo : 1.0f;
}

// A vertex's state while the regions are divided, one 64-bit word so that an offer is taken by
// one compare-and-swap when the flooding runs on several threads: its path cost's bits in the
// high half (for a vertex without a region, its best offer's so far) and its region in the
// low half, with kFinal once the region is final (before that the region of its best offer, 0
// for none). Costs are never negative, so the bits of two costs order as the costs do, and of
// two offers to a vertex the better one (lower cost, then lower region) is the lesser word.
using Site = std::uint64_t;
constexpr std::uint32_t kFinal = 0x80000000u;

Site site_of(float cost, std::uint32_t label) {
    return std::uint64_t{std::bit_cast<std::uint32_t>(cost)} << 32 | label;
}
float cost_of(Site s) {
    return std::bit_cast<float>(static_cast<std::uint32_t>(s >> 32));
}
std::uint32_t label_of(Site s) {
    return static_cast<std::uint32_t>(s);
}
std::uint32_t region_of(Site s) {
    return label_of(s) & ~kFinal;
}
bool is_final(Site s) {
    return (s & kFinal) != 0;
}

// Each finer region's region here: the one most of its vertices that kept a region are in
// (ties to the lower id; 0 when none kept one).
std::vector<std::uint32_t> finer_to_here(const std::vector<std::uint32_t>& finer,
                                         const std::vector<Site>& sites) {
    std::uint32_t top = 0;
    for (const auto f : finer) top = std::max(top, f);
    std::vector<std::uint64_t> pairs;  // (finer region, region here), for kept vertices
    for (std::size_t v = 0; v < sites.size(); ++v)
        if (label_of(sites[v]) != 0 && finer[v] != 0)
            pairs.push_back(std::uint64_t{finer[v]} << 32 | label_of(sites[v]));
    std::sort(pairs.begin(), pairs.end());
    std::vector<std::uint32_t> out(std::size_t{top} + 1, 0);
    std::vector<std::size_t> best(out.size(), 0);
    for (std::size_t i = 0; i < pairs.size();) {
        std::size_t j = i;
        while (j < pairs.size() && pairs[j] == pairs[i]) ++j;
        const auto f = static_cast<std::uint32_t>(pairs[i] >> 32);
        if (j - i > best[f]) {
            best[f] = j - i;
            out[f] = static_cast<std::uint32_t>(pairs[i]);
        }
        i = j;
    }
    return out;
}

double edge_length(const TriangleMesh& mesh, std::size_t a, std::size_t b) {
    const auto& p = mesh.positions()[a];
    const auto& q = mesh.positions()[b];
    return std::sqrt(double(p[0] - q[0]) * (p[0] - q[0]) + double(p[1] - q[1]) * (p[1] - q[1]) +
                     double(p[2] - q[2]) * (p[2] - q[2]));
}

// The edges' mean length, and the least length of the edges at each block of 2^kBlockShift
// consecutive vertices (+infinity for a block without edges). The costs, hence the labels,
// depend on the sum's last bits: it is taken in vertex order, on one thread, over the lengths
// that a wave of blocks has made on every thread (each block its own lengths and least).
constexpr std::size_t kBlockShift = 12;
struct EdgeLengths {
    double mean = 1;
    std::vector<double> least;  // by block: vertex >> kBlockShift
};

EdgeLengths edge_lengths(const TriangleMesh& mesh, const detail::PassProgress& pass) {
    EdgeLengths out;
    const std::size_t n = mesh.vertex_count();
    const std::size_t blocks = (n >> kBlockShift) + 1;
    out.least.assign(blocks, std::numeric_limits<double>::infinity());
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
                                  double least = std::numeric_limits<double>::infinity();
                                  const std::size_t last = std::min(n, (b + 1) << kBlockShift);
                                  for (std::size_t v = b << kBlockShift; v < last; ++v)
                                      for (const i32 w : mesh.neighbors_of(v)) {
                                          mine.push_back(edge_length(mesh, v, idx(w)));
                                          least = std::min(least, mine.back());
                                      }
                                  out.least[b] = least;
                              }
                          });
        for (std::size_t b = b0; b < b1; ++b) {
            for (const double len : lengths[b - b0]) sum += len;
            count += lengths[b - b0].size();
        }
    }
    out.mean = count == 0 || sum <= 0 ? 1.0 : sum / double(count);
    return out;
}

// The flooding of step 3 (see the top of the file), in batches of offers that cannot change
// one another, each taken on every thread.
//
// An offer to u from w costs cost(w) + |field(u) - mean(r)| + step * len(u, w) / mean edge, in
// floats: at least cost(w) + least_[block of w], that block's least step (rounded down). So
// once the offers up to cost D are taken, the offers of cost below E = min over them of (cost
// + least step of its vertex's block) are all final: anything they offer costs E or more. A
// batch is such a run of offers, popped from the queue in order; its offers are taken in any
// order, on any thread, and the queue gets their offers after. Every vertex thus gets the
// same region and cost as with one offer taken at a time (the lowest (cost, region) of its
// neighbours' offers, whatever their order), and the labels do not depend on the threads. A
// step that adds nothing (costs so high that the least step rounds away) makes batches of one
// offer, taken as before.
class Flooding {
  public:
    Flooding(const TriangleMesh& mesh, const std::vector<float>& field, std::vector<Site>& sites,
             const std::vector<float>& mean, float step, const EdgeLengths& lengths)
        : mesh_(mesh),
          field_(field),
          sites_(sites),
          mean_(mean),
          step_(step),
          mean_edge_(lengths.mean) {
        least_.reserve(lengths.least.size());
        for (const double len : lengths.least) {
            const float s = step * static_cast<float>(len / lengths.mean);
            least_.push_back(std::nextafter(s, 0.0f));  // (below the step of any edge there)
        }
    }

    // Offers from w (in a region) to the vertices around it without one.
    template <bool kShared, class Emit>
    void offer_around(std::size_t w, Emit&& emit) const {
        const Site at = load<kShared>(sites_[w]);
        const std::uint32_t region = region_of(at);
        const float from = cost_of(at), centre = mean_[region];
        for (const i32 nw : mesh_.neighbors_of(w)) {
            const std::size_t u = idx(nw);
            Site current = load<kShared>(sites_[u]);
            if (is_final(current)) continue;
            const double len = edge_length(mesh_, u, w);
            const float c =
                from + std::fabs(field_[u] - centre) + step_ * static_cast<float>(len / mean_edge_);
            const Site offer = site_of(c, region);
            if constexpr (kShared) {
                std::atomic_ref<Site> ref(sites_[u]);
                bool taken = false;
                while (!is_final(current) && offer < current)
                    if ((taken =
                             ref.compare_exchange_weak(current, offer, std::memory_order_relaxed)))
                        break;
                if (!taken) continue;
            } else {
                if (offer >= current) continue;
                sites_[u] = offer;
            }
            emit(Step{c, static_cast<i32>(u), region});
        }
    }

    // Takes offer s if it is still its vertex's best: the vertex's region is final, and its
    // neighbours get offers. Returns whether it was taken.
    template <bool kShared, class Emit>
    bool take(const Step& s, Emit&& emit) const {
        Site& site = sites_[idx(s.vertex)];
        const Site expected = site_of(s.cost, s.label);
        if (load<kShared>(site) != expected) return false;  // a better offer came, or final
        if constexpr (kShared)
            std::atomic_ref<Site>(site).store(expected | kFinal, std::memory_order_relaxed);
        else
            site = expected | kFinal;
        offer_around<kShared>(idx(s.vertex), emit);
        return true;
    }

    // The least cost an offer made by taking s can have.
    float reach(const Step& s) const { return s.cost + least_[idx(s.vertex) >> kBlockShift]; }

    void prefetch(const Step& s) const {
        detail::prefetch_around(mesh_, idx(s.vertex), sites_, field_, mesh_.positions());
    }

  private:
    template <bool kShared>
    static Site load(Site& s) {
        if constexpr (kShared)
            return std::atomic_ref<Site>(s).load(std::memory_order_relaxed);
        else
            return s;
    }

    const TriangleMesh& mesh_;
    const std::vector<float>& field_;
    std::vector<Site>& sites_;
    const std::vector<float>& mean_;
    float step_;
    double mean_edge_;
    std::vector<float> least_;  // by block of vertices: the least step of an edge there
};

}  // namespace

namespace {

// 1. Absorbed vertices leave their regions: the sites' labels are the regions left (their
// costs 0 until the flooding); 1b. with a finer scale's labels, absorbed vertices first go
// with their finer region. Progress 0 to 0.03.
std::vector<Site> leave_regions(const std::vector<std::uint8_t>& absorbed,
                                const std::vector<std::uint32_t>& labels,
                                const std::vector<std::uint32_t>* finer,
                                const ProgressFn& progress) {
    const std::size_t n = labels.size();
    // (Passes over every vertex, the large blocks made a slice at a time: their first touch
    // is slow, docs/performance.md.)
    const auto pass = [&](double from) {
        return detail::PassProgress(progress, from, from + 0.015, "divide");
    };
    std::vector<Site> sites;
    detail::assign_in_slices(sites, n, Site{0}, pass(0));
    constexpr std::size_t kGrain = std::size_t{1} << 14;  // (passes of each vertex its own)
    detail::parallel_slices(n, kGrain, progress, 0.015, 0.03, "divide",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t v = r.begin(); v < r.end(); ++v)
                                    sites[v] = site_of(0.0f, absorbed[v] ? 0 : labels[v]);
                            });
    if (finer) {
        const auto here = finer_to_here(*finer, sites);
        for (std::size_t v = 0; v < n; ++v)
            if (absorbed[v]) sites[v] = site_of(0.0f, here[(*finer)[v]]);
    }
    return sites;
}

// 2. The part of each region connected to its seed's own vertices; the other vertices of
// regions lose their label. Returns how many did.
std::size_t keep_seed_parts(const TriangleMesh& mesh, const reeb::ReebGraph& graph,
                            const Segmentation& segmentation, std::vector<Site>& sites) {
    const std::size_t n = sites.size();
    std::size_t detached = 0;
    const auto neighbours = [&](std::size_t v, auto&& f) {
        for (const i32 w : mesh.neighbors_of(v)) f(idx(w));
    };
    std::vector<std::uint8_t> kept(n, 0);
    std::vector<std::size_t> stack;
    // (The seeds' vertices found in one pass in vertex order: a seed node's list holds
    // the vertices absorbed into it too, most of the surface, in an order scattered over
    // it. The parts kept are the same in any order.)
    const auto& seeds = segmentation.seeds;
    for (std::size_t seed = 0; seed < n; ++seed) {
        const std::uint32_t label = label_of(sites[seed]);
        if (label == 0 || kept[seed] || label > seeds.size() ||
            graph.vertex_nodes[seed] != seeds[label - 1])
            continue;
        kept[seed] = 1;
        stack.push_back(seed);
        while (!stack.empty()) {
            const std::size_t v = stack.back();
            stack.pop_back();
            neighbours(v, [&](std::size_t u) {
                if (label_of(sites[u]) != label || kept[u]) return;
                kept[u] = 1;
                stack.push_back(u);
            });
        }
    }
    for (std::size_t v = 0; v < n; ++v)
        if (label_of(sites[v]) != 0 && !kept[v]) {
            sites[v] = site_of(0.0f, 0);
            ++detached;
        }
    return detached;
}

// The vertices left without a label opened to offers (an infinite cost), the others final;
// returns how many are to be labelled. Progress 0.23 to 0.245.
std::size_t open_unlabelled(std::vector<Site>& sites, const ProgressFn& progress) {
    const std::size_t n = sites.size();
    constexpr std::size_t kGrain = std::size_t{1} << 14;  // (passes of each vertex its own)
    std::atomic<std::size_t> unlabelled{0};  // (the absorbed and detached, less those kept)
    detail::parallel_slices(
        n, kGrain, progress, 0.23, 0.245, "divide", [&](const tbb::blocked_range<std::size_t>& r) {
            std::size_t here = 0;
            for (std::size_t v = r.begin(); v < r.end(); ++v) {
                if (label_of(sites[v]) == 0) {
                    sites[v] = site_of(std::numeric_limits<float>::infinity(), 0);
                    ++here;
                } else {
                    sites[v] |= kFinal;
                }
            }
            unlabelled += here;
        });
    const std::size_t to_label = unlabelled.load();
    return to_label;
}

// Each region's mean of the field over the vertices it kept (area-weighted), fixed for the
// flooding; progress 0.245 to 0.26.
std::vector<float> region_means(const TriangleMesh& mesh, const std::vector<float>& field,
                                const std::vector<Site>& sites, std::size_t region_count,
                                const ProgressFn& progress) {
    const std::size_t n = sites.size();
    const auto pass = [&](double from) {
        return detail::PassProgress(progress, from, from + 0.015, "divide");
    };
    std::vector<double> sum(region_count + 1, 0.0), weight(region_count + 1, 0.0);
    const auto summed = pass(0.245);
    for (std::size_t v = 0; v < n; ++v) {
        summed.at(v, n);
        if (label_of(sites[v]) == 0) continue;
        const double a = mesh.vertex_areas.empty() ? 1.0 : mesh.vertex_areas[v];
        sum[region_of(sites[v])] += a * field[v];
        weight[region_of(sites[v])] += a;
    }
    std::vector<float> mean(sum.size(), 0.0f);
    for (std::size_t r = 1; r < mean.size(); ++r)
        mean[r] = weight[r] > 0 ? static_cast<float>(sum[r] / weight[r]) : 0.0f;
    return mean;
}

// 3. The flooding from the regions' edges, in batches of offers; progress 0.26 to 1.
void flood(const TriangleMesh& mesh, const Flooding& flooding, const std::vector<Site>& sites,
           std::size_t to_label, std::size_t parallel_batch, const ProgressFn& progress) {
    const std::size_t n = sites.size();
    const auto neighbours = [&](std::size_t v, auto&& f) {
        for (const i32 w : mesh.neighbors_of(v)) f(idx(w));
    };
    const auto pass = [&](double from) {
        return detail::PassProgress(progress, from, from + 0.015, "divide");
    };
    // (A path's cost never falls below the cost of the vertex it leaves, so the offers wait in
    // a monotone queue: core/radix_heap.hpp.)
    detail::RadixHeap<Step> heap;
    const auto queue = [&](const Step& s) { heap.push(s); };
    const auto fronts = pass(0.26);
    for (std::size_t w = 0; w < n; ++w)
        if (fronts.at(w, n); is_final(sites[w])) {
            bool edge = false;
            neighbours(w, [&](std::size_t u) { edge |= !is_final(sites[u]); });
            if (edge) flooding.offer_around<false>(w, queue);
        }
    report_progress(progress, 0.3, "divide");
    // Batches of offers (above): taken on every thread when there are parallel_batch of them
    // or more, else in order here. Each slice of a batch queues its offers in its own list.
    const bool threads =
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) > 1;
    constexpr std::size_t kMaxBatch = std::size_t{1} << 16, kSlices = 8, kAheadSteps = 4;
    std::vector<Step> batch;
    std::array<std::vector<Step>, kSlices> offers;
    std::size_t labelled = 0;
    while (!heap.empty()) {
        batch.clear();
        float end = std::numeric_limits<float>::infinity();
        do {
            batch.push_back(heap.pop());
            end = std::min(end, flooding.reach(batch.back()));
        } while (batch.size() < kMaxBatch && !heap.empty() && heap.peek()->cost < end);
        const std::size_t before = labelled;
        if (!threads || batch.size() < parallel_batch) {
            // (The next offer's memory is asked for while this one is taken: popped in cost
            // order, the vertices are scattered over the surface.)
            for (std::size_t i = 0; i < batch.size(); ++i) {
                if (i + 1 < batch.size())
                    flooding.prefetch(batch[i + 1]);
                else if (const Step* next = heap.peek())
                    flooding.prefetch(*next);
                labelled += flooding.take<false>(batch[i], queue);
            }
        } else {
            std::array<std::size_t, kSlices> taken{};
            tbb::parallel_for(
                tbb::blocked_range<std::size_t>(0, kSlices, 1),
                [&](const tbb::blocked_range<std::size_t>& r) {
                    for (std::size_t k = r.begin(); k < r.end(); ++k) {
                        const std::size_t first = batch.size() * k / kSlices,
                                          last = batch.size() * (k + 1) / kSlices;
                        const auto keep = [&](const Step& s) { offers[k].push_back(s); };
                        for (std::size_t i = first; i < std::min(last, first + kAheadSteps); ++i)
                            flooding.prefetch(batch[i]);
                        for (std::size_t i = first; i < last; ++i) {
                            if (i + kAheadSteps < last) flooding.prefetch(batch[i + kAheadSteps]);
                            taken[k] += flooding.take<true>(batch[i], keep);
                        }
                    }
                });
            for (std::size_t k = 0; k < kSlices; ++k) {
                labelled += taken[k];
                for (const Step& s : offers[k]) heap.push(s);
                offers[k].clear();
            }
        }
        if ((labelled >> 16) != (before >> 16))
            report_progress(progress, 0.3 + 0.7 * double(labelled) / double(to_label), "divide");
    }
}

}  // namespace

namespace internal {

DivideCounts divide_absorbed(const TriangleMesh& mesh, const reeb::ReebGraph& graph,
                             const std::vector<float>& field,
                             const std::vector<std::uint8_t>& absorbed, Segmentation& segmentation,
                             const std::vector<std::uint32_t>* finer, const ProgressFn& progress,
                             std::size_t parallel_batch, Residency& memory) {
    const std::size_t n = mesh.vertex_count();
    if (finer && finer->size() != n)
        throw Error("segment", "divide_absorbed: the finer labels do not match the mesh");
    auto& labels = segmentation.labels;  // as grown until the end, then as divided
    // (The field may be away until Stage::flood: checked after it.)
    const auto disagree = [] {
        return Error("segment", "divide_absorbed: the field, flags, labels and mesh disagree");
    };
    if (absorbed.size() != n || labels.size() != n || graph.vertex_nodes.size() != n)
        throw disagree();
    DivideCounts counts;
    for (std::size_t v = 0; v < n; ++v) counts.absorbed += absorbed[v] != 0;
    if (counts.absorbed == 0) {
        memory.enter(Stage::flood, progress);
        memory.enter(Stage::relabel);
        if (field.size() != n) throw disagree();
        report_progress(progress, 1, "divide");
        return counts;
    }
    std::vector<Site> sites = leave_regions(absorbed, labels, finer, progress);
    counts.detached = keep_seed_parts(mesh, graph, segmentation, sites);
    report_progress(progress, 0.2, "divide");
    // The graph and the flags are read no more: the flooding's stage takes 0.2 to 0.4 of the
    // progress and the steps after 0.4 to 1 (their fractions 0.2 to 1 mapped there).
    memory.enter(Stage::flood, scaled_progress(progress, 0.2, 0.4));
    if (field.size() != n) throw disagree();
    const ProgressFn later = scaled_progress(progress, 0.25, 1);
    // 3. Flooding from the regions' edges: the shortest paths in the metric where a step
    // into u for region r costs |field(u) - mean(r)| plus a constant per mean edge length.
    const float step = kStepShare * field_spread(field);
    const EdgeLengths lengths =
        edge_lengths(mesh, detail::PassProgress(later, 0.2, 0.23, "divide"));
    // cost: a labelled vertex's path cost; for the others, the best offer so far (with the
    // offer's region in the label), so that only better offers are queued (the same result as
    // queuing every one: costs grow along a path, so a vertex's first offer taken is its
    // cheapest).
    const std::size_t to_label = open_unlabelled(sites, later);
    const std::vector<float> mean =
        region_means(mesh, field, sites, segmentation.seeds.size(), later);
    const Flooding flooding(mesh, field, sites, mean, step, lengths);
    flood(mesh, flooding, sites, to_label, parallel_batch, later);
    report_progress(later, 1, "divide");
    memory.enter(Stage::relabel);
    if (labels.size() != n) throw disagree();
    for (std::size_t v = 0; v < n; ++v) {
        if (!is_final(sites[v]))
            throw Error("segment", "divide_absorbed: vertex " + std::to_string(v) +
                                       " is in no region (no region in its mesh component)");
        const std::uint32_t region = region_of(sites[v]);
        counts.relabelled += region != labels[v];
        labels[v] = region;
    }
    return counts;
}

}  // namespace internal

DivideCounts divide_absorbed(const TriangleMesh& mesh, const reeb::ReebGraph& graph,
                             const std::vector<float>& field,
                             const std::vector<std::uint8_t>& absorbed, Segmentation& segmentation,
                             const std::vector<std::uint32_t>* finer, const ProgressFn& progress,
                             Residency& memory) {
    return internal::divide_absorbed(mesh, graph, field, absorbed, segmentation, finer, progress,
                                     internal::kParallelBatch, memory);
}

}  // namespace terrain::segment
