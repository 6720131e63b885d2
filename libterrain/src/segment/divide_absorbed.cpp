

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

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "../core/indices.hpp"
#include "../core/pass_progress.hpp"
#include "../core/radix_heap.hpp"
#include "../mesh/prefetch_around.hpp"
#include "terrain/core/error.hpp"

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

// A vertex's state while the regions are divided, in one array so that the flooding reads one
// place a vertex: its path cost (for a vertex without a region, its best offer so far), its
// field value, and its region: the region it is in once kFinal is set, before that the region
// of its best offer (0 for none).
struct Site {
    float cost;
    float field;
    std::uint32_t label;
};
constexpr std::uint32_t kFinal = 0x80000000u;

std::uint32_t region_of(const Site& s) {
    return s.label & ~kFinal;
}

// Each finer region's region here: the one most of its vertices that kept a region are in
// (ties to the lower id; 0 when none kept one).
std::vector<std::uint32_t> finer_to_here(const std::vector<std::uint32_t>& finer,
                                         const std::vector<Site>& sites) {
    std::uint32_t top = 0;
    for (const auto f : finer) top = std::max(top, f);
    std::vector<std::uint64_t> pairs;  // (finer region, region here), for kept vertices
    for (std::size_t v = 0; v < sites.size(); ++v)
        if (sites[v].label != 0 && finer[v] != 0)
            pairs.push_back(std::uint64_t{finer[v]} << 32 | sites[v].label);
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
    const auto& p = mesh.positions[a];
    const auto& q = mesh.positions[b];
    return std::sqrt(double(p[0] - q[0]) * (p[0] - q[0]) + double(p[1] - q[1]) * (p[1] - q[1]) +
                     double(p[2] - q[2]) * (p[2] - q[2]));
}

double mean_edge_length(const TriangleMesh& mesh, const detail::PassProgress& pass) {
    double sum = 0;
    std::size_t count = 0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        pass.at(v, mesh.vertex_count());
        for (const i32 w : mesh.neighbors_of(v)) {
            sum += edge_length(mesh, v, idx(w));
            ++count;
        }
    }
    return count == 0 || sum <= 0 ? 1.0 : sum / double(count);
}

}  // namespace

DivideCounts divide_absorbed(const TriangleMesh& mesh, const reeb::ReebGraph& graph,
                             const std::vector<float>& field,
                             const std::vector<std::uint8_t>& absorbed, Segmentation& segmentation,
                             const std::vector<std::uint32_t>* finer, const ProgressFn& progress) {
    const std::size_t n = mesh.vertex_count();
    if (finer && finer->size() != n)
        throw Error("segment", "divide_absorbed: the finer labels do not match the mesh");
    auto& labels = segmentation.labels;  // as grown until the end, then as divided
    if (field.size() != n || absorbed.size() != n || labels.size() != n ||
        graph.vertex_nodes.size() != n)
        throw Error("segment", "divide_absorbed: the field, flags, labels and mesh disagree");
    DivideCounts counts;
    for (std::size_t v = 0; v < n; ++v) counts.absorbed += absorbed[v] != 0;
    if (counts.absorbed == 0) {
        report_progress(progress, 1, "divide");
        return counts;
    }
    // (Passes over every vertex, the large blocks made a slice at a time: their first touch
    // is slow, docs/performance.md.)
    const auto pass = [&](double from) {
        return detail::PassProgress(progress, from, from + 0.015, "divide");
    };
    // 1. Absorbed vertices leave their regions: the sites' labels are the regions left.
    std::vector<Site> sites;
    detail::assign_in_slices(sites, n, Site{0.0f, 0.0f, 0}, pass(0));
    constexpr std::size_t kGrain = std::size_t{1} << 14;  // (passes of each vertex its own)
    detail::parallel_slices(n, kGrain, progress, 0.015, 0.03, "divide",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t v = r.begin(); v < r.end(); ++v) {
                                    sites[v].field = field[v];
                                    sites[v].label = absorbed[v] ? 0 : labels[v];
                                }
                            });
    // 1b. With a finer scale's labels: absorbed vertices first go with their finer region.
    if (finer) {
        const auto here = finer_to_here(*finer, sites);
        for (std::size_t v = 0; v < n; ++v)
            if (absorbed[v]) sites[v].label = here[(*finer)[v]];
    }
    const auto neighbours = [&](std::size_t v, auto&& f) {
        for (const i32 w : mesh.neighbors_of(v)) f(idx(w));
    };
    // 2. The part of each region connected to its seed's own vertices.
    {
        std::vector<std::uint8_t> kept(n, 0);
        std::vector<std::size_t> stack;
        // (The seeds' vertices found in one pass in vertex order: a seed node's list holds
        // the vertices absorbed into it too, most of the surface, in an order scattered over
        // it. The parts kept are the same in any order.)
        const auto& seeds = segmentation.seeds;
        for (std::size_t seed = 0; seed < n; ++seed) {
            const std::uint32_t label = sites[seed].label;
            if (label == 0 || kept[seed] || label > seeds.size() ||
                graph.vertex_nodes[seed] != seeds[label - 1])
                continue;
            kept[seed] = 1;
            stack.push_back(seed);
            while (!stack.empty()) {
                const std::size_t v = stack.back();
                stack.pop_back();
                neighbours(v, [&](std::size_t u) {
                    if (sites[u].label != label || kept[u]) return;
                    kept[u] = 1;
                    stack.push_back(u);
                });
            }
        }
        for (std::size_t v = 0; v < n; ++v)
            if (sites[v].label != 0 && !kept[v]) {
                sites[v].label = 0;
                ++counts.detached;
            }
    }
    report_progress(progress, 0.2, "divide");
    // 3. Flooding from the regions' edges: the shortest paths in the metric where a step
    // into u for region r costs |field(u) - mean(r)| plus a constant per mean edge length.
    const float step = kStepShare * field_spread(field);
    const double mean_edge =
        mean_edge_length(mesh, detail::PassProgress(progress, 0.2, 0.23, "divide"));
    // cost: a labelled vertex's path cost; for the others, the best offer so far (with the
    // offer's region in the label), so that only better offers are queued (the same result as
    // queuing every one: costs grow along a path, so a vertex's first offer taken is its
    // cheapest).
    std::atomic<std::size_t> unlabelled{0};  // (the absorbed and detached, less those kept)
    detail::parallel_slices(n, kGrain, progress, 0.23, 0.245, "divide",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                std::size_t here = 0;
                                for (std::size_t v = r.begin(); v < r.end(); ++v) {
                                    if (sites[v].label == 0) {
                                        sites[v].cost = std::numeric_limits<float>::infinity();
                                        ++here;
                                    } else {
                                        sites[v].label |= kFinal;
                                    }
                                }
                                unlabelled += here;
                            });
    const std::size_t to_label = unlabelled.load();
    std::size_t labelled = 0;
    // Each region's mean of the field over the vertices it kept (area-weighted), fixed for
    // the flooding.
    std::vector<double> sum(segmentation.seeds.size() + 1, 0.0),
        weight(segmentation.seeds.size() + 1, 0.0);
    const auto summed = pass(0.245);
    for (std::size_t v = 0; v < n; ++v) {
        summed.at(v, n);
        if (sites[v].label == 0) continue;
        const double a = mesh.vertex_areas.empty() ? 1.0 : mesh.vertex_areas[v];
        sum[region_of(sites[v])] += a * sites[v].field;
        weight[region_of(sites[v])] += a;
    }
    std::vector<float> mean(sum.size(), 0.0f);
    for (std::size_t r = 1; r < mean.size(); ++r)
        mean[r] = weight[r] > 0 ? static_cast<float>(sum[r] / weight[r]) : 0.0f;
    // (A path's cost never falls below the cost of the vertex it leaves, so the offers wait in
    // a monotone queue: core/radix_heap.hpp.)
    detail::RadixHeap<Step> heap;
    // Offers from w (in a region) to the vertices around it without one.
    const auto push_around = [&](std::size_t w) {
        const std::uint32_t region = region_of(sites[w]);
        const float from = sites[w].cost, centre = mean[region];
        neighbours(w, [&](std::size_t u) {
            Site& site = sites[u];
            if (site.label & kFinal) return;
            const double len = edge_length(mesh, u, w);
            const float c =
                from + std::fabs(site.field - centre) + step * static_cast<float>(len / mean_edge);
            if (c > site.cost || (c == site.cost && region >= site.label)) return;
            site.cost = c;
            site.label = region;
            heap.push({c, static_cast<i32>(u), region});
        });
    };
    const auto fronts = pass(0.26);
    for (std::size_t w = 0; w < n; ++w)
        if (fronts.at(w, n); sites[w].label & kFinal) {
            bool edge = false;
            neighbours(w, [&](std::size_t u) { edge |= !(sites[u].label & kFinal); });
            if (edge) push_around(w);
        }
    report_progress(progress, 0.3, "divide");
    while (!heap.empty()) {
        const Step s = heap.pop();
        // (The next vertex's memory is asked for while this one is handled: popped in cost
        // order, the vertices are scattered over the surface.)
        if (const Step* next = heap.peek())
            detail::prefetch_around(mesh, idx(next->vertex), sites, mesh.positions);
        Site& site = sites[idx(s.vertex)];
        if ((site.label & kFinal) || s.cost != site.cost || s.label != site.label) continue;
        site.label |= kFinal;
        push_around(idx(s.vertex));
        if ((++labelled & 0xffff) == 0)
            report_progress(progress, 0.3 + 0.7 * double(labelled) / double(to_label), "divide");
    }
    report_progress(progress, 1, "divide");
    for (std::size_t v = 0; v < n; ++v) {
        if (!(sites[v].label & kFinal))
            throw Error("segment", "divide_absorbed: vertex " + std::to_string(v) +
                                       " is in no region (no region in its mesh component)");
        const std::uint32_t region = region_of(sites[v]);
        counts.relabelled += region != labels[v];
        labels[v] = region;
    }
    return counts;
}

}  // namespace terrain::segment
