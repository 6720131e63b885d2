

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

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <string>

#include "../core/indices.hpp"
#include "../core/pass_progress.hpp"
#include "terrain/core/error.hpp"

namespace terrain::segment {

namespace {

using detail::i32;
using detail::idx;

struct Step {
    float cost;
    i32 vertex;
    std::uint32_t label;
    bool operator>(const Step& o) const {
        if (cost != o.cost) return cost > o.cost;
        if (vertex != o.vertex) return vertex > o.vertex;
        return label > o.label;
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

// Each finer region's region here: the one most of its vertices that kept a region are in
// (ties to the lower id; 0 when none kept one).
std::vector<std::uint32_t> finer_to_here(const std::vector<std::uint32_t>& finer,
                                         const std::vector<std::uint32_t>& labels) {
    std::uint32_t top = 0;
    for (const auto f : finer) top = std::max(top, f);
    std::vector<std::uint64_t> pairs;  // (finer region, region here), for kept vertices
    for (std::size_t v = 0; v < labels.size(); ++v)
        if (labels[v] != 0 && finer[v] != 0)
            pairs.push_back(std::uint64_t{finer[v]} << 32 | labels[v]);
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
    auto& labels = segmentation.labels;
    if (field.size() != n || absorbed.size() != n || labels.size() != n ||
        graph.vertex_nodes.size() != n)
        throw Error("segment", "divide_absorbed: the field, flags, labels and mesh disagree");
    DivideCounts counts;
    const std::vector<std::uint32_t> before = labels;
    for (std::size_t v = 0; v < n; ++v)
        if (absorbed[v]) {
            labels[v] = 0;
            ++counts.absorbed;
        }
    if (counts.absorbed == 0) {
        report_progress(progress, 1, "divide");
        return counts;
    }
    // 1b. With a finer scale's labels: absorbed vertices first go with their finer region.
    if (finer) {
        const auto here = finer_to_here(*finer, labels);
        for (std::size_t v = 0; v < n; ++v)
            if (absorbed[v]) labels[v] = here[(*finer)[v]];
    }
    const auto neighbours = [&](std::size_t v, auto&& f) {
        for (const i32 w : mesh.neighbors_of(v)) f(idx(w));
    };
    // 2. The part of each region connected to its seed's own vertices.
    std::vector<std::uint8_t> kept(n, 0);
    std::vector<std::size_t> stack;
    for (std::size_t r = 0; r < segmentation.seeds.size(); ++r) {
        const i32 s = segmentation.seeds[r];
        const auto label = static_cast<std::uint32_t>(r + 1);
        for (i32 i = graph.node_vertex_offsets[idx(s)]; i < graph.node_vertex_offsets[idx(s) + 1];
             ++i) {
            const std::size_t v = idx(graph.node_vertices[idx(i)]);
            if (labels[v] != label || kept[v]) continue;
            kept[v] = 1;
            stack.push_back(v);
        }
        while (!stack.empty()) {
            const std::size_t v = stack.back();
            stack.pop_back();
            neighbours(v, [&](std::size_t u) {
                if (labels[u] != label || kept[u]) return;
                kept[u] = 1;
                stack.push_back(u);
            });
        }
    }
    for (std::size_t v = 0; v < n; ++v)
        if (labels[v] != 0 && !kept[v]) {
            labels[v] = 0;
            ++counts.detached;
        }
    report_progress(progress, 0.2, "divide");
    // 3. Flooding from the regions' edges: the shortest paths in the metric where a step
    // into u for region r costs |field(u) - mean(r)| plus a constant per mean edge length.
    const float step = kStepShare * field_spread(field);
    const double mean_edge =
        mean_edge_length(mesh, detail::PassProgress(progress, 0.2, 0.2, "divide"));
    // cost: a labelled vertex's path cost; for the others, the best offer so far (from
    // `offer`), so that only better offers are queued (the same result as queuing every
    // one: costs grow along a path, so a vertex's first offer taken is its cheapest).
    // (Passes over every vertex from 0.2 to 0.3 of the progress, the large blocks made a slice
    // at a time: their first touch is slow, docs/performance.md.)
    const auto pass = [&](double from) {
        return detail::PassProgress(progress, from, from + 0.015, "divide");
    };
    std::vector<float> cost;
    std::vector<std::uint32_t> offer;
    detail::assign_in_slices(cost, n, 0.0f, pass(0.2));
    detail::assign_in_slices(offer, n, std::uint32_t{0}, pass(0.215));
    const auto unlabelled = pass(0.23);
    for (std::size_t v = 0; v < n; ++v)
        if (unlabelled.at(v, n); labels[v] == 0) cost[v] = std::numeric_limits<float>::infinity();
    // Each region's mean of the field over the vertices it kept (area-weighted), fixed for
    // the flooding.
    std::vector<double> sum(segmentation.seeds.size() + 1, 0.0),
        weight(segmentation.seeds.size() + 1, 0.0);
    const auto summed = pass(0.245);
    for (std::size_t v = 0; v < n; ++v) {
        summed.at(v, n);
        if (labels[v] == 0) continue;
        const double a = mesh.vertex_areas.empty() ? 1.0 : mesh.vertex_areas[v];
        sum[labels[v]] += a * field[v];
        weight[labels[v]] += a;
    }
    std::vector<float> mean(sum.size(), 0.0f);
    for (std::size_t r = 1; r < mean.size(); ++r)
        mean[r] = weight[r] > 0 ? static_cast<float>(sum[r] / weight[r]) : 0.0f;
    std::priority_queue<Step, std::vector<Step>, std::greater<Step>> heap;
    const auto push_around = [&](std::size_t w) {
        neighbours(w, [&](std::size_t u) {
            if (labels[u] != 0) return;
            const double len = edge_length(mesh, u, w);
            const float c = cost[w] + std::fabs(field[u] - mean[labels[w]]) +
                            step * static_cast<float>(len / mean_edge);
            if (c > cost[u] || (c == cost[u] && labels[w] >= offer[u])) return;
            cost[u] = c;
            offer[u] = labels[w];
            heap.push({c, static_cast<i32>(u), labels[w]});
        });
    };
    const auto fronts = pass(0.26);
    for (std::size_t w = 0; w < n; ++w)
        if (fronts.at(w, n); labels[w] != 0) {
            bool edge = false;
            neighbours(w, [&](std::size_t u) { edge |= labels[u] == 0; });
            if (edge) push_around(w);
        }
    // (the vertices to label: the absorbed ones and those detached, less those kept)
    std::size_t to_label = 0, labelled = 0;
    const auto counted = pass(0.275);
    for (std::size_t v = 0; v < n; ++v) {
        counted.at(v, n);
        to_label += labels[v] == 0;
    }
    report_progress(progress, 0.3, "divide");
    while (!heap.empty()) {
        const Step s = heap.top();
        heap.pop();
        const std::size_t u = idx(s.vertex);
        if (labels[u] != 0 || s.cost != cost[u] || s.label != offer[u]) continue;
        labels[u] = s.label;
        cost[u] = s.cost;
        push_around(u);
        if ((++labelled & 0xffff) == 0)
            report_progress(progress, 0.3 + 0.7 * double(labelled) / double(to_label), "divide");
    }
    report_progress(progress, 1, "divide");
    for (std::size_t v = 0; v < n; ++v) {
        if (labels[v] == 0)
            throw Error("segment", "divide_absorbed: vertex " + std::to_string(v) +
                                       " is in no region (no region in its mesh component)");
        counts.relabelled += labels[v] != before[v];
    }
    return counts;
}

}  // namespace terrain::segment
