

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
#include <atomic>
#include <limits>
#include <string>

#include "divide_absorbed_internal.hpp"
#include "flooding.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/indices.hpp"
#include "terrain/internal/core/pass_progress.hpp"

namespace terrain::segment {

namespace {

using detail::i32;
using detail::idx;
using internal::is_final;
using internal::kFinal;
using internal::label_of;
using internal::region_of;
using internal::Site;
using internal::site_of;

// The cost of one mean edge length, as a share of the field's spread: without it, paths
// through noise of small steps would cross the body before any region took its surroundings.
constexpr float kStepShare = 0.01f;

// The field's range over the vertices that keep their region (1 when flat).
float field_spread(const std::vector<float>& field) {
    if (field.empty()) return 1.0f;
    const auto [lo, hi] = std::minmax_element(field.begin(), field.end());
    return *hi > *lo ? *hi - *lo : 1.0f;
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

// How many parts the flooding takes: `asked` (1: in order), or with 0 and enough vertices,
// kPartsPerThread a thread (at least two threads' worth: the parts' queues are smaller and
// their vertices closer in memory, so that even one thread floods parts faster than the
// whole in order).
std::size_t flood_parts(std::size_t asked, std::size_t vertices) {
    if (asked != 0) return asked;
    if (vertices < internal::kPartsFrom) return 1;
    const auto threads = static_cast<std::size_t>(
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    return std::min<std::size_t>(internal::kMostParts,
                                 internal::kPartsPerThread * std::max<std::size_t>(2, threads));
}

}  // namespace

namespace internal {

DivideCounts divide_absorbed(const TriangleMesh& mesh, const reeb::ReebGraph& graph,
                             const std::vector<float>& field,
                             const std::vector<std::uint8_t>& absorbed, Segmentation& segmentation,
                             const std::vector<std::uint32_t>* finer, const ProgressFn& progress,
                             std::size_t parts, Residency& memory) {
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
    const double mean_edge = mean_edge_length(mesh, later, 0.2, 0.23);
    // cost: a labelled vertex's path cost; for the others, the best offer so far (with the
    // offer's region in the label), so that only better offers are queued (the same result as
    // queuing every one: costs grow along a path, so a vertex's first offer taken is its
    // cheapest).
    const std::size_t to_label = open_unlabelled(sites, later);
    const std::vector<float> mean =
        region_means(mesh, field, sites, segmentation.seeds.size(), later);
    const Flooding flooding(mesh, field, sites, mean, step, mean_edge);
    if (const std::size_t k = flood_parts(parts, n); k > 1)
        flood_in_parts(flooding, k, to_label, scaled_progress(later, 0.26, 1));
    else
        flood_in_order(flooding, to_label, scaled_progress(later, 0.26, 1));
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
    return internal::divide_absorbed(mesh, graph, field, absorbed, segmentation, finer, progress, 0,
                                     memory);
}

}  // namespace terrain::segment
