// Building the Reeb graph (paper s.3.1, METHOD.md s.3): checks the input and picks the
// algorithm. Both are exact and give the same graph node for node:
//   - the contour tree (contour_tree.cpp), when every component of the mesh is a disk or a
//     sphere, so that the graph is a tree: join and split trees by union-find, merged;
//   - the contour-tracking sweep (contour_sweep.cpp) for handles and holes (loops).
// Both start from the same order of events (event_order.cpp); `automatic` tries the contour
// tree, which finds out on the way whether the mesh has loops, and falls back to the sweep on
// the same events. Shared parts: half_edges.cpp, link_components.cpp; the graph's own
// utilities (summaries, checks) are in reeb_graph.cpp.

#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "contour_sweep.hpp"
#include "contour_tree.hpp"
#include "event_order.hpp"
#include "terrain/core/error.hpp"
#include "terrain/reeb/reeb_graph.hpp"

namespace terrain::reeb {

bool reeb_is_tree(const TriangleMesh& mesh, const ProgressFn& progress) {
    return internal::loop_free(mesh, progress);
}

ReebGraph build_reeb_graph(const TriangleMesh& mesh, const std::vector<float>& field,
                           const ReebOptions& options, const ProgressFn& progress) {
    if (field.size() != mesh.vertex_count())
        throw Error("reeb", "the field has " + std::to_string(field.size()) +
                                " values for a mesh of " + std::to_string(mesh.vertex_count()) +
                                " vertices");
    for (std::size_t v = 0; v < field.size(); ++v)
        if (std::isnan(field[v]))
            throw Error("reeb", "the field is NaN at vertex " + std::to_string(v));
    if (mesh.vertex_count() >= static_cast<std::size_t>(INT32_MAX / 4))
        throw Error("reeb", "the mesh is too large (more than 500 million vertices)");
    ReebGraph g;
    Residency& memory = options.memory ? *options.memory : all_resident();
    memory.enter(Stage::reeb_events);
    if (options.algorithm == ReebAlgorithm::sweep) {
        memory.enter(Stage::reeb_loops);
        internal::contour_sweep(mesh, field, g, progress, false);
        return g;
    }
    internal::order_events(mesh, field, g, scaled_progress(progress, 0, 0.2));
    if (internal::contour_tree(mesh, g, progress, memory)) {
        report_progress(progress, 1.0, "reeb");
        return g;
    }
    if (options.known_tree)
        throw Error("reeb", "the mesh was said to be a tree (known_tree) but has handles or holes");
    if (options.algorithm == ReebAlgorithm::contour_tree)
        throw Error("reeb",
                    "the contour-tree algorithm needs a mesh whose components are disks "
                    "or spheres; this one has handles or holes");
    // Handles or holes: the sweep, on the same events.
    memory.enter(Stage::reeb_loops);
    const ProgressFn rest = [&](double f, std::string_view message) {
        return progress ? progress(0.3 + 0.7 * f, message) : true;
    };
    internal::contour_sweep(mesh, field, g, rest, true);
    return g;
}

}  // namespace terrain::reeb
