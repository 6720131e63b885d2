#pragma once
// Triangulates a DEM into a georeferenced 2-manifold mesh on its body (METHOD.md section 1):
// one vertex per valid pixel centre, each 2x2 block of valid pixels split along its shorter
// 3-D diagonal (ties: the top-left to bottom-right one), three valid pixels give one
// triangle. A grid global in longitude closes its seam and collapses each pole row to one
// vertex (body frame). Pinched vertices (fans meeting only at them) are split, one vertex
// per fan; valid pixels in no triangle are left out. See docs/mesh.md.

#include <optional>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::mesh {

struct DemToMeshOptions {
    std::optional<MeshFrame> frame;  // body or map; unset: default_frame(dem)
    bool close_global = true;        // close the seam and the poles of a global grid
    // Release the triangles (TriangleMesh::release_triangles) before the areas and the
    // adjacency are made, which then walk them from the grid: for a caller that reads them
    // only through detail::for_each_triangle, or makes them again (restore_triangles). Not
    // done for a grid with a split pinch or fewer than 3 columns.
    bool release_triangles = false;
};

// body for planetary and geographic CRSs, map for projected Earth CRSs and local grids.
MeshFrame default_frame(const Dem& dem);

// Throws terrain::Error (stage "mesh") when the DEM gives no triangle or the frame does not
// apply (body frame without a CRS).
TriangleMesh dem_to_mesh(const Dem& dem, const DemToMeshOptions& options = {},
                         const ProgressFn& progress = {});

// Places again the positions of a DEM mesh made of `dem` (dem_to_mesh) that freed them
// (TriangleMesh::release_positions): the same floats, from the same computation. Nothing to
// do when the mesh holds them. Throws terrain::Error (stage "mesh") for another grid.
void restore_positions(const Dem& dem, TriangleMesh& mesh, const ProgressFn& progress = {});
// The same, with the DEM's values read from `heights` (row-major, one a pixel; `dem`'s own
// values are not read and may be freed): the DEM's values held as floats, every one exactly
// (pipeline::segment's packed heights), give the same positions as the doubles.
void restore_positions(const Dem& dem, const std::vector<float>& heights, TriangleMesh& mesh,
                       const ProgressFn& progress = {});

// For each pixel (row-major), the vertex made from it, or -1 (NoData, isolated). The pixels
// of a collapsed pole row all map to the pole vertex; a split pinch maps to its first copy.
// A copy of mesh.pixel_vertex when the mesh has it.
std::vector<std::int32_t> pixel_to_vertex(const TriangleMesh& mesh, const Dem& dem);
// mesh.pixel_vertex when the mesh holds it (no copy), else the map made into `storage`.
const std::vector<std::int32_t>& pixel_vertices(const TriangleMesh& mesh, const Dem& dem,
                                                std::vector<std::int32_t>& storage);
// The same, into `out`.
void fill_pixel_to_vertex(const TriangleMesh& mesh, const Dem& dem, std::vector<std::int32_t>& out);

}  // namespace terrain::mesh
