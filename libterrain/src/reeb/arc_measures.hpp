#pragma once
// Private: the two measures of an arc that decide whether it is cancelled (paper s.3.2,
// METHOD.md s.4), written once for the simplification and for arc_metrics.

#include <cmath>

namespace terrain::reeb::internal {

// Persistence: how far apart the values of the arc's two ends are.
inline float persistence(float lower_value, float upper_value) {
    return std::fabs(upper_value - lower_value);
}

// Area ratio: the area of the arc's regular nodes plus each end's area shared equally among
// the end's arcs, over the whole mesh's area (total_area from mesh_area_or_one). The ends'
// shares are added first; add_list_area(s) returns s plus the regular nodes' area, node by
// node or at once, as the caller holds it.
template <class AddListArea>
double area_ratio(double lower_area, double lower_arcs, double upper_area, double upper_arcs,
                  AddListArea&& add_list_area, double total_area) {
    const double ends = lower_area / lower_arcs + upper_area / upper_arcs;
    return add_list_area(ends) / total_area;
}

// The area that area ratios divide by: 1 for a mesh without area (ratios stay finite).
inline double mesh_area_or_one(double total_area) {
    return total_area <= 0 ? 1.0 : total_area;
}

}  // namespace terrain::reeb::internal
