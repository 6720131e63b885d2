#pragma once
// Mesh files: .off, .ply, .obj in (CGAL's readers), binary PLY out.

#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/memory_budget.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::io {

struct ReadMeshOptions {
    // Repair instead of refusing: merge duplicate points, drop degenerate faces, triangulate
    // polygons, orient consistently, split non-manifold vertices and edges.
    bool repair = false;
};

// Reads a triangle mesh. Without repair, non-triangular faces, indices out of range,
// degenerate faces (repeated vertex or zero area), edges in more than two faces, faces
// oriented against their neighbours and pinched vertices are refused with a
// terrain::Error (stage "mesh") naming the first bad element.
TriangleMesh read_mesh(const std::string& path, const ReadMeshOptions& options = {},
                       const ProgressFn& progress = {});
// The same with the memory plan of the work that follows (pipeline::memory_plan), checked
// from the counts of the file's header before CGAL reads it; the overload above checks the
// peak of reading alone (MemoryPlan's defaults).
TriangleMesh read_mesh(const std::string& path, const ReadMeshOptions& options,
                       const ProgressFn& progress, const MemoryPlan& memory);

// True for the extensions read_mesh reads (.off .ply .obj, any case).
bool is_mesh_file(const std::string& path);

// A per-vertex property written beside x y z: `float name` from `values`, or `uint name`
// from `labels` when that is set instead.
struct VertexProperty {
    std::string name;
    const std::vector<float>* values = nullptr;
    const std::vector<std::uint32_t>* labels = nullptr;
};

// Binary little-endian PLY: double x y z (absolute metres), int col row for DEM meshes,
// float area, the extra properties, then the faces. Atomic; refuses to overwrite unless asked.
void write_ply(const TriangleMesh& mesh, const std::string& path, bool overwrite,
               const std::vector<VertexProperty>& extra = {});

}  // namespace terrain::io
