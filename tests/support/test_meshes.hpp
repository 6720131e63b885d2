#pragma once
// Analytic meshes for the topology tests: grids from height functions (with NoData holes),
// tori and a thickened plate with holes (a closed surface of any genus).

#include <cstdint>
#include <functional>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::test {

// A w x h DEM without CRS (1 m pixels) with z = height(col, row); NaN makes NoData.
Dem grid_dem(int w, int h, const std::function<double(int, int)>& height);

// A mesh from triangles over explicit points (finish_mesh applied).
TriangleMesh make_mesh(const std::vector<std::array<double, 3>>& points,
                       const std::vector<std::array<std::int32_t, 3>>& triangles);

// A torus with major radius R, tube radius r, nu x nv quads. `upright`: its axis is
// horizontal (the y axis), so z has one minimum, two saddles and one maximum; otherwise its
// axis is vertical and every ring of constant tube angle is level.
TriangleMesh torus_mesh(double R, double r, int nu, int nv, bool upright);

// The surface of a plate (w x h unit cells, 1 thick) with `holes` square holes in a row: a
// closed surface of genus `holes`.
TriangleMesh plate_mesh(int w, int h, int holes);

// The same mesh with its vertices renumbered by `perm` (new index of old vertex v is perm[v])
// and its triangles rotated and reordered; fields follow with permute_field.
TriangleMesh permute_mesh(const TriangleMesh& mesh, const std::vector<std::int32_t>& perm);
std::vector<float> permute_field(const std::vector<float>& field,
                                 const std::vector<std::int32_t>& perm);

// The number of mesh-connected pieces of each label 1..count (index label - 1): a region is
// connected when its count is 1. Labels must be in 1..count.
std::vector<int> region_pieces(const TriangleMesh& mesh, const std::vector<std::uint32_t>& labels,
                               std::uint32_t count);

// Uniform noise in [0, 100), reproducible from the seed.
std::vector<float> noise_field(std::size_t n, unsigned seed);

}  // namespace terrain::test
