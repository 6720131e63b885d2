// A mesh's topology: edges, boundary edges and loops, components, Euler characteristic.
#include "terrain/mesh/triangle_mesh.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "terrain/internal/core/disjoint_sets.hpp"
#include "terrain/internal/mesh/grid_triangles.hpp"

namespace terrain {

MeshTopology mesh_topology(const TriangleMesh& mesh) {
    if (!mesh.grid_adjacency() && mesh.neighbor_offsets.size() != mesh.vertex_count() + 1) {
        TriangleMesh finished = mesh;  // no adjacency yet
        finish_mesh(finished);
        return mesh_topology(finished);
    }
    MeshTopology topo;
    topo.vertices = mesh.vertex_count();
    topo.faces = mesh.triangle_count();
    const auto first = first_edge_slots(mesh);
    const auto slot = [&](std::int32_t a, std::int32_t b) {
        const auto nb = mesh.neighbors_of(std::size_t(a));
        return first[std::size_t(a)] +
               static_cast<std::uint64_t>(std::lower_bound(nb.begin(), nb.end(), b) - nb.begin());
    };
    // Each edge (a < b) counts its triangles at the slot a -> b.
    // (Triangles through for_each_triangle: a DEM mesh may have released them.)
    using Corners = std::array<std::int32_t, 3>;
    std::vector<std::uint8_t> uses(first.back(), 0);
    detail::for_each_triangle(mesh, [&](std::size_t, const Corners& t) {
        for (int k = 0; k < 3; ++k) {
            const auto s = slot(std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]));
            uses[s] = static_cast<std::uint8_t>(std::min(uses[s] + 1, 3));
        }
    });
    detail::DisjointSets<std::uint32_t> sets(topo.vertices);
    // Boundary loops: components of the graph of boundary edges.
    std::vector<std::uint32_t> boundary_vertices;
    for (std::size_t v = 0; v < topo.vertices; ++v) {
        const auto nb = mesh.neighbors_of(v);
        for (std::size_t i = 0; i < nb.size(); ++i) {
            const auto w = static_cast<std::size_t>(nb[i]);
            if (w <= v) continue;
            ++topo.edges;
            if (uses[first[v] + i] != 1) continue;
            ++topo.boundary_edges;
            boundary_vertices.push_back(static_cast<std::uint32_t>(v));
            sets.unite(static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(v));
        }
    }
    for (auto& v : boundary_vertices) v = sets.find(v);
    std::sort(boundary_vertices.begin(), boundary_vertices.end());
    topo.boundary_loops =
        static_cast<std::size_t>(std::unique(boundary_vertices.begin(), boundary_vertices.end()) -
                                 boundary_vertices.begin());
    // Components by triangles.
    sets.reset(topo.vertices);
    std::vector<char> used(topo.vertices, 0);
    detail::for_each_triangle(mesh, [&](std::size_t, const Corners& t) {
        for (int k = 1; k < 3; ++k) sets.unite(std::uint32_t(t[k]), std::uint32_t(t[0]));
        for (int k = 0; k < 3; ++k) used[t[k]] = 1;
    });
    for (std::size_t v = 0; v < topo.vertices; ++v)
        if (used[v] && sets.is_root(std::uint32_t(v))) ++topo.components;
    topo.euler_characteristic =
        std::int64_t(topo.vertices) - std::int64_t(topo.edges) + std::int64_t(topo.faces);
    return topo;
}

}  // namespace terrain
