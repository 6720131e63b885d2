#pragma once
// Helpers for the segment and output tests: crops of the sample DEMs cut into regions the
// tests choose (the region growing is another stage), and independent pixel areas.

#include <cstdint>
#include <functional>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::test {

// Pixels [col0, col0+width) x [row0, row0+height) of `dem`, the geotransform moved to match.
Dem crop(const Dem& dem, int col0, int row0, int width, int height);

struct SegmentedTile {
    Dem dem;
    TriangleMesh mesh;
    std::vector<float> field;  // shape index
    std::vector<std::uint32_t> labels;
    std::uint32_t region_count = 0;
    segment::RegionGraph graph;
    std::vector<std::uint32_t> pixels;  // segment::label_pixels
};

// Meshes `dem`, computes its shape index and labels each vertex with label_of(col, row); the
// labels used are renumbered 1..N in increasing order.
SegmentedTile segment_tile(Dem dem, const std::function<std::uint32_t(int, int)>& label_of);

// Voronoi cells of an nx x ny jittered grid of seed pixels (distance in pixels, ties to the
// lowest seed).
std::function<std::uint32_t(int, int)> voronoi_cells(const Dem& dem, int nx, int ny);

// The area of pixel (col, row) computed here, independently of the library: GeographicLib's
// geodesic PolygonArea of its four corners on the body (the DEM's CRS to its geographic CRS
// through GDAL), or |det| of the geotransform without CRS.
double pixel_area(const Dem& dem, int col, int row);

// The sum of pixel_area over the pixels with `label` (any non-zero label when label == 0).
double labelled_area(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                     std::uint32_t label = 0);

}  // namespace terrain::test
