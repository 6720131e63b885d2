#pragma once
// How the regions of one segmentation overlap those of another (a sweep's scale i and i+1).

#include <cstdint>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::segment {

struct Overlap {
    std::uint32_t region = 0;  // a region of the other segmentation
    double area_m2 = 0;        // the area the two share
    double fraction = 0;       // area_m2 / the area of the region it is listed under
};

struct RegionLineage {
    std::uint32_t region = 0;
    double area_m2 = 0;
    std::vector<Overlap> overlaps;  // by region id
    // Its parent: the region of the other segmentation it shares the most area with (ties
    // to the lower id; 0 for a region with no area), that area, and its share of the region.
    std::uint32_t parent = 0;
    double parent_area_m2 = 0;
    double parent_share = 0;
};

// For each region of `from` (ids 1..from_count), the regions of `to` it overlaps. Areas are
// measured as region_graph measures area_m2: pixel footprints on the body for a DEM mesh
// (dem != nullptr), vertex areas for a mesh file; so one region's overlaps add up to its
// area. On a DEM the regions of pixels in no triangle that label_pixels adds are counted
// too (after from_count / to_count when these count the vertices' regions only).
std::vector<RegionLineage> region_lineage(const TriangleMesh& mesh, const Dem* dem,
                                          const std::vector<std::uint32_t>& from,
                                          std::uint32_t from_count,
                                          const std::vector<std::uint32_t>& to,
                                          std::uint32_t to_count);

// The share of the regions' area inside their parents (each region weighted by its area):
// 1 when every region lies in one region of the other segmentation.
double mean_parent_share(const std::vector<RegionLineage>& lineage);

}  // namespace terrain::segment
