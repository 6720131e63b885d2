// The measures of every arc of a finished graph (arc_metrics), as the simplification sees
// them (arc_measures.hpp): reported per arc in the Reeb JSON, and checked by the tests
// against the thresholds after a simplification.

#include "arc_measures.hpp"

#include <algorithm>
#include <vector>

#include "terrain/internal/core/indices.hpp"
#include "terrain/reeb/simplify.hpp"

namespace terrain::reeb {

using detail::i32;
using detail::idx;

namespace {

// The area of each node: its vertices' areas (1 each on a mesh without areas), added in
// increasing vertex order.
std::vector<double> node_areas(const TriangleMesh& mesh, const ReebGraph& g) {
    std::vector<double> area(g.node_count(), 0.0);
    for (std::size_t v = 0; v < g.vertex_nodes.size(); ++v)
        area[idx(g.vertex_nodes[v])] += mesh.vertex_areas.empty() ? 1.0 : mesh.vertex_areas[v];
    return area;
}

}  // namespace

ArcMetrics arc_metrics(const TriangleMesh& mesh, const ReebGraph& g) {
    const auto area = node_areas(mesh, g);
    double total = 0;
    for (const double a : area) total += a;
    total = internal::mesh_area_or_one(total);
    const NodeArcs inc = node_arcs(g);
    ArcMetrics m;
    m.persistence.resize(g.arc_count());
    m.area_ratio.resize(g.arc_count());
    for (std::size_t a = 0; a < g.arc_count(); ++a) {
        const auto [lo, hi] = g.arcs[a];
        m.persistence[a] = internal::persistence(g.node_values[idx(lo)], g.node_values[idx(hi)]);
        const auto add_list_area = [&](double sum) {
            for (i32 i = g.arc_offsets[a]; i < g.arc_offsets[a + 1]; ++i)
                sum += area[idx(g.arc_nodes[idx(i)])];
            return sum;
        };
        m.area_ratio[a] =
            internal::area_ratio(area[idx(lo)], static_cast<double>(inc.degree(lo)), area[idx(hi)],
                                 static_cast<double>(inc.degree(hi)), add_list_area, total);
    }
    return m;
}

double total_area(const TriangleMesh& mesh) {
    if (mesh.vertex_areas.empty()) return internal::mesh_area_or_one(double(mesh.vertex_count()));
    double total = 0;
    for (const double a : mesh.vertex_areas) total += a;
    return internal::mesh_area_or_one(total);
}

double area_ratio_for_area(const TriangleMesh& mesh, double min_area) {
    return std::min(100.0, 100.0 * min_area / total_area(mesh));
}

}  // namespace terrain::reeb
