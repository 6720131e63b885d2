// The Reeb graph as a value (paper s.3.1, METHOD.md s.3): names of node kinds and of the
// paper's link classes (s.2.1, its table of lower/upper link components), and what can be
// read off a finished graph without its mesh: the arcs at each node, counts (critical nodes,
// components, loops = arcs - critical nodes + components, the sum of PL indices) and a check
// of its invariants, used by the tests and by `terrain reeb`. Construction is in
// build_reeb_graph.cpp and the files it names.

#include <numeric>
#include <string>

#include "terrain/internal/core/disjoint_sets.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/reeb/reeb_graph.hpp"

namespace terrain::reeb {

const char* to_string(NodeKind kind) {
    switch (kind) {
        case NodeKind::minimum:
            return "min";
        case NodeKind::maximum:
            return "max";
        case NodeKind::saddle:
            return "saddle";
        default:
            return "regular";
    }
}

const char* to_string(LinkClass c) {
    switch (c) {
        case LinkClass::morse_minimum:
            return "morse_minimum";
        case LinkClass::degenerate_minimum:
            return "degenerate_minimum";
        case LinkClass::morse_maximum:
            return "morse_maximum";
        case LinkClass::degenerate_maximum:
            return "degenerate_maximum";
        case LinkClass::morse_saddle:
            return "morse_saddle";
        case LinkClass::degenerate_saddle:
            return "degenerate_saddle";
        case LinkClass::asymmetric_saddle:
            return "asymmetric_saddle";
        default:
            return "regular";
    }
}

LinkClass classify_link(int lower, int upper) {
    if (upper == 0) return lower <= 1 ? LinkClass::morse_maximum : LinkClass::degenerate_maximum;
    if (lower == 0) return upper == 1 ? LinkClass::morse_minimum : LinkClass::degenerate_minimum;
    if (lower == upper)
        return lower == 1   ? LinkClass::regular
               : lower == 2 ? LinkClass::morse_saddle
                            : LinkClass::degenerate_saddle;
    return LinkClass::asymmetric_saddle;
}

std::size_t ReebGraph::memory_bytes() const {
    auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
    return bytes(node_values) + bytes(node_kinds) + bytes(node_lower_links) +
           bytes(node_upper_links) + bytes(node_vertex_offsets) + bytes(node_vertices) +
           bytes(vertex_nodes) + bytes(node_arcs) + bytes(arcs) + bytes(arc_offsets) +
           bytes(arc_nodes);
}

NodeArcs node_arcs(const ReebGraph& g) {
    NodeArcs out;
    out.offsets.assign(g.node_count() + 1, 0);
    for (const auto& a : g.arcs) {
        ++out.offsets[static_cast<std::size_t>(a[0]) + 1];
        ++out.offsets[static_cast<std::size_t>(a[1]) + 1];
    }
    std::partial_sum(out.offsets.begin(), out.offsets.end(), out.offsets.begin());
    out.arcs.resize(static_cast<std::size_t>(out.offsets.back()));
    std::vector<std::int32_t> fill(out.offsets.begin(), out.offsets.end() - 1);
    for (std::size_t a = 0; a < g.arcs.size(); ++a)
        for (int end = 0; end < 2; ++end)
            out.arcs[static_cast<std::size_t>(fill[static_cast<std::size_t>(g.arcs[a][end])]++)] =
                static_cast<std::int32_t>(a);
    return out;
}

ReebSummary summarize(const ReebGraph& g, const ProgressFn& progress) {
    const detail::PassProgress by_arc(progress, 0, 0.5, "reeb: summary"),
        by_node(progress, 0.5, 1, "reeb: summary");
    ReebSummary s;
    s.nodes = g.node_count();
    s.arcs = g.arc_count();
    // Components: the arcs join their ends' sets.
    detail::DisjointSets<std::int32_t> components(g.node_count());
    for (std::size_t a = 0; a < g.arc_count(); ++a) {
        by_arc.at(a, g.arc_count());
        components.unite(g.arcs[a][1], g.arcs[a][0]);
    }
    for (std::size_t n = 0; n < g.node_count(); ++n) {
        by_node.at(n, g.node_count());
        const NodeKind k = g.node_kinds[n];
        if (k == NodeKind::regular) continue;
        ++s.critical;
        if (k == NodeKind::minimum) ++s.minima;
        if (k == NodeKind::maximum) ++s.maxima;
        if (k == NodeKind::saddle) ++s.saddles;
        if (components.is_root(static_cast<std::int32_t>(n))) ++s.components;
        const int lo = g.node_lower_links[n], up = g.node_upper_links[n];
        s.index_sum += (lo == 0 || up == 0) ? 1.0 : 1.0 - 0.5 * (lo + up);
    }
    s.loops = s.arcs + s.components - s.critical;
    return s;
}

std::string check_reeb_graph(const ReebGraph& g, const std::vector<float>& field) {
    const std::size_t n_nodes = g.node_count();
    if (g.vertex_nodes.size() != field.size()) return "vertex_nodes has the wrong size";
    std::vector<char> seen(field.size(), 0);
    for (std::size_t n = 0; n < n_nodes; ++n) {
        const auto b = g.node_vertex_offsets[n], e = g.node_vertex_offsets[n + 1];
        if (b >= e) return "node " + std::to_string(n) + " has no vertex";
        for (auto i = b; i < e; ++i) {
            const auto v = static_cast<std::size_t>(g.node_vertices[static_cast<std::size_t>(i)]);
            if (seen[v]++) return "vertex " + std::to_string(v) + " is in two nodes";
            if (g.vertex_nodes[v] != static_cast<std::int32_t>(n))
                return "vertex " + std::to_string(v) + " maps to the wrong node";
            if (field[v] != g.node_values[n])
                return "vertex " + std::to_string(v) + " differs from its node's value";
        }
    }
    for (std::size_t v = 0; v < seen.size(); ++v)
        if (!seen[v]) return "vertex " + std::to_string(v) + " is in no node";
    std::vector<int> down(n_nodes, 0), up(n_nodes, 0);
    std::vector<char> placed(n_nodes, 0);
    for (std::size_t a = 0; a < g.arc_count(); ++a) {
        const auto [lo, hi] = g.arcs[a];
        if (!g.is_critical(lo) || !g.is_critical(hi))
            return "arc " + std::to_string(a) + " ends at a regular node";
        if (lo == hi) return "arc " + std::to_string(a) + " is a self-loop";
        ++up[static_cast<std::size_t>(lo)];
        ++down[static_cast<std::size_t>(hi)];
        float prev = g.node_values[static_cast<std::size_t>(lo)];
        for (auto i = g.arc_offsets[a]; i < g.arc_offsets[a + 1]; ++i) {
            const auto r = static_cast<std::size_t>(g.arc_nodes[static_cast<std::size_t>(i)]);
            if (g.is_critical(static_cast<std::int32_t>(r)) ||
                g.node_arcs[r] != static_cast<std::int32_t>(a) || placed[r]++)
                return "arc " + std::to_string(a) + " lists node " + std::to_string(r) + " wrongly";
            if (g.node_values[r] < prev)
                return "arc " + std::to_string(a) + " is not sorted by value";
            prev = g.node_values[r];
        }
        if (g.node_values[static_cast<std::size_t>(hi)] < prev)
            return "arc " + std::to_string(a) + " goes downwards";
    }
    for (std::size_t n = 0; n < n_nodes; ++n) {
        const NodeKind k = g.node_kinds[n];
        const bool ok = k == NodeKind::regular   ? (placed[n] && !down[n] && !up[n])
                        : k == NodeKind::minimum ? (down[n] == 0)
                        : k == NodeKind::maximum
                            ? (up[n] == 0 && down[n] > 0)
                            : (down[n] > 0 && up[n] > 0 && down[n] + up[n] >= 3);
        if (!ok) return "node " + std::to_string(n) + " (" + to_string(k) + ") has wrong arcs";
    }
    return {};
}

}  // namespace terrain::reeb
