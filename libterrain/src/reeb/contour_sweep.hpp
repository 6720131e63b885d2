#pragma once
// Private: the contour-tracking sweep, the construction for meshes of any genus.

#include <vector>

#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/reeb/reeb_graph.hpp"

namespace terrain::reeb::internal {

// Builds the Reeb graph of `field` into g by the contour-tracking sweep. `ordered`: the
// graph's events are already set (order_events), else they are sorted here.
void contour_sweep(const TriangleMesh& mesh, const std::vector<float>& field, ReebGraph& g,
                   const ProgressFn& progress, bool ordered);

}  // namespace terrain::reeb::internal
