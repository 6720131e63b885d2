// Each region's range of area thresholds (area_range.hpp): the simplification continued level
// by level, each level on the graph the one before left.
//
// A level reads the graph's vertices for their areas only, and its regular nodes for their
// areas and for the arc they are in: their own values matter only when a cancellation moves an
// arc's end (an extremum-extremum cancellation, the last of a component). So each level runs on
// the graph before it folded: one stand-in vertex per node, holding the node's area, and each
// arc's regular nodes one node, holding their areas, at the value of the middle one. The
// cancellations, their order and the areas they compare are then those of the mesh (the areas
// added in another order, so equal up to rounding), and a level costs the graph's critical
// nodes and arcs, a few per region, instead of the mesh's vertices.
#include "terrain/segment/area_range.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "terrain/core/error.hpp"
#include "terrain/internal/core/release.hpp"

namespace terrain::segment {
namespace {

using i32 = std::int32_t;

// The most nodes an arc's regular nodes are folded into.
constexpr std::size_t kGroups = 16;

// A graph folded on a mesh of its stand-in vertices (vertex n is node n), and the new number
// of each node of the graph it was folded from.
struct Folded {
    TriangleMesh mesh;
    reeb::ReebGraph graph;
    std::vector<i32> renumbered;
};

// `graph`'s critical nodes kept and each arc's regular nodes made up to kGroups nodes (runs of
// them along the arc), every node one vertex of its summed area (`vertex_areas`: of the
// graph's vertices; empty for 1 each). A run sits at its middle node's value; the first and
// the last of an arc at the value of the node nearest the arc's end, which is what a node
// with many arcs orders them by.
Folded fold(reeb::ReebGraph&& graph, const std::vector<float>& vertex_areas) {
    const auto& g = graph;
    const std::size_t n = g.node_count();
    std::vector<double> area(n, 0.0);
    for (std::size_t v = 0; v < g.vertex_nodes.size(); ++v)
        area[std::size_t(g.vertex_nodes[v])] += vertex_areas.empty() ? 1.0 : vertex_areas[v];
    Folded f;
    auto& out = f.graph;
    std::vector<double> sums;
    const auto add = [&](std::size_t m, reeb::NodeKind kind, float value, i32 arc) {
        sums.push_back(0);
        out.node_values.push_back(value);
        out.node_kinds.push_back(kind);
        out.node_lower_links.push_back(g.node_lower_links[m]);
        out.node_upper_links.push_back(g.node_upper_links[m]);
        out.node_arcs.push_back(arc);
        return i32(out.node_values.size() - 1);
    };
    f.renumbered.assign(n, -1);
    for (std::size_t m = 0; m < n; ++m)
        if (g.node_kinds[m] != reeb::NodeKind::regular)
            f.renumbered[m] = add(m, g.node_kinds[m], g.node_values[m], -1);
    out.arcs.reserve(g.arc_count());
    out.arc_offsets.assign(1, 0);
    for (std::size_t a = 0; a < g.arc_count(); ++a) {
        out.arcs.push_back(
            {f.renumbered[std::size_t(g.arcs[a][0])], f.renumbered[std::size_t(g.arcs[a][1])]});
        const std::size_t first = std::size_t(g.arc_offsets[a]);
        const std::size_t count = std::size_t(g.arc_offsets[a + 1]) - first;
        const std::size_t runs = std::min(count, kGroups);
        for (std::size_t j = 0; j < runs; ++j) {
            const std::size_t lo = first + j * count / runs, hi = first + (j + 1) * count / runs;
            const std::size_t at = j == 0 ? lo : j + 1 == runs ? hi - 1 : (lo + hi) / 2;
            const auto node = std::size_t(g.arc_nodes[at]);
            const i32 k = add(node, reeb::NodeKind::regular, g.node_values[node], i32(a));
            for (std::size_t i = lo; i < hi; ++i) f.renumbered[std::size_t(g.arc_nodes[i])] = k;
            out.arc_nodes.push_back(k);
        }
        out.arc_offsets.push_back(i32(out.arc_nodes.size()));
    }
    // The areas added in the old nodes' order.
    for (std::size_t m = 0; m < n; ++m) sums[std::size_t(f.renumbered[m])] += area[m];
    graph = reeb::ReebGraph{};
    const std::size_t folded = out.node_values.size();
    out.vertex_nodes.resize(folded);
    std::iota(out.vertex_nodes.begin(), out.vertex_nodes.end(), 0);
    out.node_vertices = out.vertex_nodes;
    out.node_vertex_offsets.resize(folded + 1);
    std::iota(out.node_vertex_offsets.begin(), out.node_vertex_offsets.end(), 0);
    f.mesh.vertex_areas.assign(sums.begin(), sums.end());
    f.mesh.edit_positions().assign(folded, {0.0f, 0.0f, 0.0f});
    return f;
}

// The area each standing seed heads in a folded graph: its node's and the regular nodes' of
// its arcs (the part of the graph a region grown from it starts with); 0 for the others.
std::vector<double> extents(const Folded& f, const std::vector<i32>& vertex,
                            const std::vector<std::uint8_t>& standing) {
    const auto& g = f.graph;
    const auto& area = f.mesh.vertex_areas;  // (node n is stand-in vertex n)
    std::vector<double> head(g.node_count(), -1.0);
    for (std::size_t r = 0; r < vertex.size(); ++r)
        if (standing[r]) head[std::size_t(vertex[r])] = area[std::size_t(vertex[r])];
    for (std::size_t a = 0; a < g.arc_count(); ++a)
        for (const i32 end : g.arcs[a])
            if (head[std::size_t(end)] >= 0)
                for (auto i = g.arc_offsets[a]; i < g.arc_offsets[a + 1]; ++i)
                    head[std::size_t(end)] += area[std::size_t(g.arc_nodes[std::size_t(i)])];
    std::vector<double> out(vertex.size(), 0.0);
    for (std::size_t r = 0; r < vertex.size(); ++r)
        if (standing[r]) out[r] = head[std::size_t(vertex[r])];
    return out;
}

}  // namespace

std::vector<double> seed_area_ranges(const TriangleMesh& mesh, reeb::ReebGraph&& graph,
                                     const std::vector<std::int32_t>& seeds,
                                     const AreaRangeOptions& options, const ProgressFn& progress) {
    if (!(options.floor_m2 > 0) || !std::isfinite(options.floor_m2))
        throw Error("segment", "the area range needs a floor above 0 m^2");
    if (!(options.step > 1) || !std::isfinite(options.step))
        throw Error("segment", "the area range's step must be a number above 1");
    if (!(options.growth >= 1))  // (infinity: the range ends with the seed alone)
        throw Error("segment", "the area range's growth must be a number >= 1");
    if (graph.vertex_nodes.size() != mesh.vertex_count())
        throw Error("segment", "the area range's graph was not made on this mesh");
    for (std::size_t r = 0; r < seeds.size(); ++r) {
        const auto s = seeds[r];
        if (s < 0 || std::size_t(s) >= graph.node_count() || !graph.is_extremum(s))
            throw Error("segment", "region " + std::to_string(r + 1) +
                                       "'s seed is not an extremum of the simplified graph");
    }
    const double total = reeb::total_area(mesh);
    // Each seed is known by its stand-in vertex: the node it is in, level after level.
    Folded level = fold(std::move(graph), mesh.vertex_areas);
    std::vector<i32> vertex(seeds.size());
    for (std::size_t r = 0; r < seeds.size(); ++r)
        vertex[r] = level.renumbered[std::size_t(seeds[r])];
    std::vector<double> to(seeds.size(), total);
    // standing: the seed is an extremum of its own; open: its range has not ended.
    std::vector<std::uint8_t> standing(seeds.size(), 1), open(seeds.size(), 1);
    std::size_t left = seeds.size();
    const auto end_range = [&](std::size_t r, double threshold) {
        if (!open[r]) return;
        open[r] = 0;
        to[r] = threshold;
        --left;
    };
    const auto first = extents(level, vertex, standing);
    const double levels =
        std::max(1.0, std::ceil(std::log(total / options.floor_m2) / std::log(options.step)));
    double done = 0;
    for (double threshold = options.floor_m2 * options.step; threshold < total && left > 0;
         threshold *= options.step, ++done) {
        reeb::SimplifyOptions next;
        next.persistence = options.persistence;
        // The same ratio as on the mesh: the threshold over the mesh's whole area.
        next.area_ratio = std::min(100.0, 100.0 * threshold / total);
        next.rewrite_field = false;
        auto simplified = reeb::simplify(
            level.mesh, std::move(level.graph), next,
            scaled_progress(progress, done / levels, std::min(1.0, (done + 1) / levels)));
        auto& g = simplified.graph;
        // A seed stands while its node is an extremum that no seed of a lower id holds
        // (seeds made one node by an extremum-extremum cancellation).
        std::vector<std::uint8_t> held(g.node_count(), 0);
        for (std::size_t r = 0; r < seeds.size(); ++r) {
            if (!standing[r]) continue;
            const auto node = g.vertex_nodes[std::size_t(vertex[r])];
            vertex[r] = node;
            if (g.is_extremum(node) && !held[std::size_t(node)]) {
                held[std::size_t(node)] = 1;
                continue;
            }
            standing[r] = 0;
            end_range(r, threshold);
        }
        level = fold(std::move(g), level.mesh.vertex_areas);
        for (std::size_t r = 0; r < seeds.size(); ++r)
            if (standing[r]) vertex[r] = level.renumbered[std::size_t(vertex[r])];
        // A seed that stands but heads more than `growth` times what it headed at the floor
        // has taken in its neighbours: its region is no longer the one of the map.
        const auto now = extents(level, vertex, standing);
        for (std::size_t r = 0; r < seeds.size(); ++r)
            if (standing[r] && now[r] > options.growth * first[r]) end_range(r, threshold);
    }
    report_progress(progress, 1.0, "segment");
    return to;
}

}  // namespace terrain::segment
