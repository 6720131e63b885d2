// Region growing over Reeb graph nodes (docs/segment.md). Candidates wait in a min-heap of
// (cost, node, region); a popped candidate whose cost rose since it was pushed (its region's
// mean moved) is pushed back with the current cost, so the pair taken is the cheapest as far
// as the heap knows. Costs that fall (a saddle losing its penalty) are pushed anew.

#include "terrain/segment/grow_regions.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <queue>
#include <vector>

#include "terrain/core/error.hpp"
#include "terrain/internal/core/indices.hpp"
#include "terrain/internal/core/pass_progress.hpp"

namespace terrain::segment {

GrowCost parse_grow_cost(const std::string& name) {
    if (const auto cost = value_named(kGrowCostNames, name)) return *cost;
    throw Error("segment", "unknown cost '" + name + "'; use graph or standard");
}

const char* to_string(GrowCost cost) {
    return name_of(kGrowCostNames, cost);
}

namespace {

using detail::i32;
using detail::idx;
using detail::kNone;

struct Candidate {
    float cost;
    i32 node, region;
    bool operator>(const Candidate& o) const {
        if (cost != o.cost) return cost > o.cost;
        if (node != o.node) return node > o.node;
        return region > o.region;
    }
};

class Grower {
  public:
    // Reports its set-up as 0 to 1 of `progress` (areas, then the graph's neighbours).
    Grower(const TriangleMesh& mesh, const reeb::ReebGraph& g, const GrowOptions& options,
           const ProgressFn& progress)
        : mesh_(mesh), g_(g), options_(options) {
        const std::size_t nn = g.node_count(), nv = g.vertex_nodes.size();
        node_region_.assign(nn, kNone);
        node_area_.assign(nn, 0.0);
        const detail::PassProgress areas(progress, 0, 0.4, "grow");
        for (std::size_t v = 0; v < nv; ++v) {
            areas.at(v, nv);
            node_area_[idx(g.vertex_nodes[v])] +=
                mesh.vertex_areas.empty() ? 1.0 : mesh.vertex_areas[v];
        }
        build_reeb_neighbours(scaled_progress(progress, 0.4, 1));
        unassigned_branches_.resize(nn);
        for (std::size_t n = 0; n < nn; ++n) unassigned_branches_[n] = nb_off_[n + 1] - nb_off_[n];
    }

    Segmentation run(const ProgressFn& progress) {
        Segmentation out;
        // Seeds: extremum nodes, numbered by their lowest vertex.
        std::vector<std::pair<i32, i32>> seeds;  // (lowest vertex, node)
        for (std::size_t n = 0; n < g_.node_count(); ++n)
            if (g_.is_extremum(static_cast<i32>(n))) {
                i32 lowest = INT32_MAX;
                for (i32 i = g_.node_vertex_offsets[n]; i < g_.node_vertex_offsets[n + 1]; ++i)
                    lowest = std::min(lowest, g_.node_vertices[idx(i)]);
                seeds.emplace_back(lowest, static_cast<i32>(n));
            }
        std::sort(seeds.begin(), seeds.end());
        region_sum_.assign(seeds.size(), 0.0);
        region_area_.assign(seeds.size(), 0.0);
        for (std::size_t r = 0; r < seeds.size(); ++r) out.seeds.push_back(seeds[r].second);
        // Progress by vertices: after the simplification a few nodes (the seeds first) hold
        // most of them.
        progress_ = &progress;
        for (std::size_t r = 0; r < seeds.size(); ++r) {
            assign(seeds[r].second, static_cast<i32>(r));
            counted(seeds[r].second);
        }
        const std::size_t total = g_.node_count();
        std::size_t assigned = seeds.size();
        bool relaxed = false;
        for (;;) {
            while (!heap_.empty()) {
                const Candidate c = heap_.top();
                heap_.pop();
                if (node_region_[idx(c.node)] != kNone) continue;
                if (!relaxed && options_.cost == GrowCost::graph && !reeb_eligible(c.node))
                    continue;
                const float now = cost(c.node, c.region, relaxed);
                if (now > c.cost) {
                    heap_.push({now, c.node, c.region});
                    continue;
                }
                assign(c.node, c.region);
                if (relaxed) ++out.relaxed_nodes;
                ++assigned;
                counted(c.node);
            }
            if (assigned == total || relaxed || seeds.empty()) break;
            // Nodes the graph constraint left out: let them join under the standard cost.
            relaxed = true;
            for (std::size_t n = 0; n < total; ++n)
                if (node_region_[n] != kNone) push_mesh_candidates(static_cast<i32>(n), true);
        }
        if (assigned != total)
            throw Error("segment", "region growing left " + std::to_string(total - assigned) +
                                       " nodes without a region (no extremum in their component)");
        out.region_count = static_cast<std::uint32_t>(seeds.size());
        out.labels.resize(g_.vertex_nodes.size());
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.labels.size(), 1 << 16),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t v = r.begin(); v < r.end(); ++v)
                                  out.labels[v] = static_cast<std::uint32_t>(
                                      node_region_[idx(g_.vertex_nodes[v])] + 1);
                          });
        report_progress(progress, 1.0, "grow");
        return out;
    }

  private:
    // Reeb-graph neighbours of every node: along its arc for a regular node, the first node
    // of each incident arc for a critical node. CSR.
    void build_reeb_neighbours(const ProgressFn& progress) {
        const std::size_t nn = g_.node_count();
        const detail::PassProgress along_arcs(progress, 0, 1, "grow");
        nb_off_.assign(nn + 1, 0);
        auto along = [&](std::size_t a, bool from_lower) {
            const i32 b = g_.arc_offsets[a], e = g_.arc_offsets[a + 1];
            if (b == e) return from_lower ? g_.arcs[a][1] : g_.arcs[a][0];
            return from_lower ? g_.arc_nodes[idx(b)] : g_.arc_nodes[idx(e - 1)];
        };
        for (std::size_t n = 0; n < nn; ++n)
            nb_off_[n + 1] = g_.is_critical(static_cast<i32>(n)) ? 0 : 2;
        for (const auto& a : g_.arcs) {
            ++nb_off_[idx(a[0]) + 1];
            ++nb_off_[idx(a[1]) + 1];
        }
        for (std::size_t n = 0; n < nn; ++n) nb_off_[n + 1] += nb_off_[n];
        nb_.resize(idx(nb_off_[nn]));
        std::vector<i32> fill(nb_off_.begin(), nb_off_.end() - 1);
        for (std::size_t a = 0; a < g_.arc_count(); ++a) {
            nb_[idx(fill[idx(g_.arcs[a][0])]++)] = along(a, true);
            nb_[idx(fill[idx(g_.arcs[a][1])]++)] = along(a, false);
            const i32 b = g_.arc_offsets[a], e = g_.arc_offsets[a + 1];
            for (i32 i = b; i < e; ++i) {
                along_arcs.at(idx(i), g_.arc_nodes.size());
                const i32 r = g_.arc_nodes[idx(i)];
                nb_[idx(fill[idx(r)]++)] = i == b ? g_.arcs[a][0] : g_.arc_nodes[idx(i - 1)];
                nb_[idx(fill[idx(r)]++)] = i + 1 == e ? g_.arcs[a][1] : g_.arc_nodes[idx(i + 1)];
            }
        }
    }

    bool reeb_eligible(i32 n) const {
        return unassigned_branches_[idx(n)] < nb_off_[idx(n) + 1] - nb_off_[idx(n)];
    }

    float cost(i32 n, i32 r, bool relaxed) const {
        const double mean = region_sum_[idx(r)] / std::max(region_area_[idx(r)], 1e-300);
        double c = std::fabs(mean - static_cast<double>(g_.node_values[idx(n)]));
        if (!relaxed && options_.cost == GrowCost::graph && unassigned_branches_[idx(n)] > 1)
            c += options_.saddle_penalty;
        return static_cast<float>(c);
    }

    void push(i32 n, i32 r, bool relaxed) { heap_.push({cost(n, r, relaxed), n, r}); }

    // Whether node n's vertices are walked in vertex order, by a pass over vertex_nodes: a
    // node's list is in the order the simplification gathered it (by value, scattered over the
    // surface), and a node with a large share of the vertices waits on memory at every step
    // of its list (on a global grid, one such node held 99 % of the vertices); walked in
    // vertex order, the vertices around each one are next to those of the last.
    bool walked(i32 n) const {
        const std::size_t count =
            idx(g_.node_vertex_offsets[idx(n) + 1] - g_.node_vertex_offsets[idx(n)]);
        return options_.walk_share > 0 && count * options_.walk_share >= g_.vertex_nodes.size();
    }

    // The distinct keys key(w) >= 0 (a node or a region) of the mesh neighbours w of node n's
    // vertices, in any order: the callers push a candidate for each, and the candidates are a
    // set (an entry pushed twice is popped twice in a row, the second time with nothing left
    // to do), so neither the order nor the repeats change what the growing does. A walked node
    // is walked on every thread, a slice of the vertices at a time; the others by their list.
    // `assigning`: n is being assigned (its vertices count towards the progress).
    template <class Key>
    const std::vector<i32>& keys_around(i32 n, bool assigning, const Key& key) {
        keys_.clear();
        const i32 first = g_.node_vertex_offsets[idx(n)], last = g_.node_vertex_offsets[idx(n) + 1];
        const auto add = [&](std::vector<i32>& to, std::size_t v) {
            for (const i32 w : mesh_.neighbors_of(v)) {
                const i32 k = key(w);
                if (k >= 0 && (to.empty() || to.back() != k)) to.push_back(k);
            }
        };
        if (!walked(n)) {
            for (i32 i = first; i < last; ++i) {
                tick(assigning ? idx(i - first) : 0);
                add(keys_, idx(g_.node_vertices[idx(i)]));
            }
            return keys_;
        }
        // The vertices from the node's lowest to its highest (read in its list, in order).
        const auto [lo, hi] =
            std::minmax_element(g_.node_vertices.begin() + first, g_.node_vertices.begin() + last);
        const std::size_t begin = idx(*lo), span = idx(*hi) + 1 - begin, count = idx(last - first);
        // (slices of 4 M vertices or more, at most 16: a report after each)
        const std::size_t slices = std::min<std::size_t>(16, 1 + (span >> 22));
        constexpr std::size_t kGrain = std::size_t{1} << 16;
        tbb::enumerable_thread_specific<std::vector<i32>> found;
        for (std::size_t s = 0; s < slices; ++s) {
            tbb::parallel_for(
                tbb::blocked_range<std::size_t>(begin + span * s / slices,
                                                begin + span * (s + 1) / slices, kGrain),
                [&](const tbb::blocked_range<std::size_t>& r) {
                    std::vector<i32>& mine = found.local();
                    for (std::size_t v = r.begin(); v < r.end(); ++v)
                        if (g_.vertex_nodes[v] == n) add(mine, v);
                    std::sort(mine.begin(), mine.end());
                    mine.erase(std::unique(mine.begin(), mine.end()), mine.end());
                });
            visited_ += count / slices;
            report(done_ + (assigning ? count * (s + 1) / slices : 0));
        }
        for (const auto& mine : found) keys_.insert(keys_.end(), mine.begin(), mine.end());
        std::sort(keys_.begin(), keys_.end());
        keys_.erase(std::unique(keys_.begin(), keys_.end()), keys_.end());
        return keys_;
    }

    // Candidates (u, r) for the unassigned nodes u touching node n (in region r) on the mesh.
    void push_mesh_candidates(i32 n, bool relaxed) {
        const i32 r = node_region_[idx(n)];
        const bool graph = !relaxed && options_.cost == GrowCost::graph;
        for (const i32 u : keys_around(n, true, [&](i32 w) {
                 const i32 u = g_.vertex_nodes[idx(w)];
                 return node_region_[idx(u)] != kNone || (graph && !reeb_eligible(u)) ? kNone : u;
             }))
            push(u, r, relaxed);
    }

    // Candidates for node u against every region it touches on the mesh.
    void push_all_regions(i32 u) {
        for (const i32 r : keys_around(
                 u, false, [&](i32 w) { return node_region_[idx(g_.vertex_nodes[idx(w)])]; }))
            push(u, r, false);
    }

    void assign(i32 n, i32 r) {
        node_region_[idx(n)] = r;
        region_sum_[idx(r)] += node_area_[idx(n)] * g_.node_values[idx(n)];
        region_area_[idx(r)] += node_area_[idx(n)];
        if (options_.cost == GrowCost::graph) {
            // Reeb neighbours: one more branch assigned; a node that just became eligible, or
            // a saddle that just lost its penalty, gets its candidates (again).
            for (i32 k = nb_off_[idx(n)]; k < nb_off_[idx(n) + 1]; ++k) {
                const i32 u = nb_[idx(k)];
                if (node_region_[idx(u)] != kNone) continue;
                const i32 before = unassigned_branches_[idx(u)]--;
                const i32 degree = nb_off_[idx(u) + 1] - nb_off_[idx(u)];
                if (before == degree || before == 2) push_all_regions(u);
            }
        }
        push_mesh_candidates(n, false);
    }

    const TriangleMesh& mesh_;
    const reeb::ReebGraph& g_;
    GrowOptions options_;
    std::vector<i32> node_region_, nb_off_, nb_, unassigned_branches_;
    std::vector<double> node_area_, region_sum_, region_area_;
    std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> heap_;
    std::vector<i32> keys_;  // keys_around()'s
    // While run() runs: its progress, the vertices of the nodes assigned so far, the vertices
    // looked at (every 2^18 a report: a node the simplification gave a large part of the
    // surface takes seconds), and the fraction reported last.
    const ProgressFn* progress_ = nullptr;
    std::size_t done_ = 0, visited_ = 0;
    double reported_ = 0;
    void report(std::size_t vertices) {
        if (!progress_) return;
        const double nv = static_cast<double>(std::max<std::size_t>(1, g_.vertex_nodes.size()));
        reported_ = std::max(reported_, static_cast<double>(vertices) / nv);
        report_progress(*progress_, reported_, "grow");
    }
    // Node n assigned: its vertices are done (a report each 2^18 of them).
    void counted(i32 n) {
        const std::size_t before = done_;
        done_ += idx(g_.node_vertex_offsets[idx(n) + 1] - g_.node_vertex_offsets[idx(n)]);
        if ((before >> 18) != (done_ >> 18)) report(done_);
    }
    // One more vertex looked at, `partial` vertices into the node being assigned.
    void tick(std::size_t partial) {
        if ((++visited_ & 0x3ffff) == 0) report(done_ + partial);
    }
};

}  // namespace

Segmentation grow_regions(const TriangleMesh& mesh, const reeb::ReebGraph& graph,
                          const GrowOptions& options, const ProgressFn& progress) {
    if (graph.vertex_nodes.size() != mesh.vertex_count())
        throw Error("segment", "the Reeb graph was not built on this mesh");
    if (!std::isfinite(options.saddle_penalty) || options.saddle_penalty < 0)
        throw Error("segment", "the saddle penalty must be a number >= 0");
    Grower grower(mesh, graph, options, scaled_progress(progress, 0, 0.1));
    return grower.run(scaled_progress(progress, 0.1, 1));
}

}  // namespace terrain::segment
