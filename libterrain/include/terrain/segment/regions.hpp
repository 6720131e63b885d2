#pragma once
// The regions of a segmentation and their adjacency graph (METHOD.md section 6): what every
// output file (label raster, polygons, graphs) says about a region, computed once from the
// mesh, the field and the per-vertex labels. See docs/outputs.md.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::segment {

// Koenderink's nine shape categories (Koenderink & van Doorn 1992, as binned by Dorai & Jain
// 1997 "COSMOS"), on the shape index mapped to [0,100] (0 = cup, 50 = saddle/planar,
// 100 = cap): cup [0, 6.25), trough [6.25, 18.75), rut [18.75, 31.25),
// saddle rut [31.25, 43.75), saddle [43.75, 56.25), saddle ridge [56.25, 68.75),
// ridge [68.75, 81.25), dome [81.25, 93.75), cap [93.75, 100].
enum class Landform : std::uint8_t {
    cup,
    trough,
    rut,
    saddle_rut,
    saddle,
    saddle_ridge,
    ridge,
    dome,
    cap,
    unknown  // no field value: a region of pixels that no triangle holds
};

// Values outside [0,100] are clamped; NaN (no value) is `unknown`.
Landform landform_of(double shape_index);
const char* to_string(Landform landform);  // "cup", ..., "saddle rut", ..., "cap", "unknown"
// The middle of a class's shape-index interval (3.125 for cup, 12.5 k, 96.875 for cap); NaN
// for unknown.
double landform_centre(Landform landform);

// What the representative points are in: lon/lat degrees on the body (a DEM with a CRS),
// the DEM's map/pixel coordinates (a DEM without CRS), or the mesh's x, y, z (file meshes).
enum class PointFrame { lonlat, map, mesh };

struct Region {
    std::uint32_t id = 0;
    std::size_t vertex_count = 0;  // mesh vertices with this label
    std::size_t pixel_count = 0;   // DEM pixels with this label in the label raster (DEM only)
    // Area in m^2: DEM meshes, the footprint of the region's pixels on the body's ellipsoid
    // (planar pixel area for a grid without CRS); file meshes, the 3-D mesh area.
    double area_m2 = 0;
    double surface_area_m2 = 0;  // 3-D mesh area (sum of vertex areas), relief included
    double field_mean = 0;       // weighted by vertex area
    double field_min = 0, field_max = 0;
    Landform landform = Landform::saddle;  // of field_mean
    // The vertex farthest from the region's boundary in mesh edges (ties: lowest index) and
    // its position: lon, lat (degrees), height (m); map x, y, height; or mesh x, y, z.
    std::int32_t representative_vertex = -1;
    std::array<double, 3> point{0, 0, 0};
    std::size_t neighbor_count = 0;  // edges of the graph at this region
    // The field's radius (metres) most of the region's vertices took when it was chosen per
    // vertex (--radius auto; ties to the smaller), 0 otherwise.
    double field_scale_m = 0;
    // The area thresholds (m^2) over which the region exists (--min-area auto): from the
    // threshold of this segmentation up to the first threshold, doubling, at which its seed is
    // cancelled (segment::seed_area_ranges); 0 for a region with no seed (pixels in no
    // triangle).
    double min_area_from_m2 = 0, min_area_to_m2 = 0;
};

// Two regions that share at least one mesh edge.
struct RegionEdge {
    std::uint32_t a = 0, b = 0;  // a < b
    // Length in metres of the boundary between them on the mesh: in each triangle whose
    // vertices carry two labels, the segment joining the midpoints of its two cut edges; in a
    // triangle with three labels, the segments from the centroid to each edge's midpoint.
    double boundary_length_m = 0;
    double contrast = 0;         // |field_mean(a) - field_mean(b)|
    std::size_t mesh_edges = 0;  // mesh edges with one end in a and the other in b
};

struct RegionGraph {
    std::vector<Region> regions;    // regions[i].id == i + 1
    std::vector<RegionEdge> edges;  // sorted by (a, b)
    PointFrame point_frame = PointFrame::mesh;
    // The CRS of the points when point_frame is lonlat (the body's geographic CRS; EPSG:4326
    // on Earth), as WKT; empty otherwise.
    std::string point_crs_wkt;
    bool has_field_scale = false;  // the regions' field_scale_m are set (--radius auto)
    bool has_area_range = false;   // their min_area_from_m2 and min_area_to_m2 are set
};

// The regions of `labels` (one per vertex, 1..region_count, every id used) with their
// properties and adjacency; on a DEM, followed by the regions of pixels only that
// label_pixels adds (vertex_count 0, field values NaN, representative_vertex -1, the point
// at their first pixel, no neighbours), and the pixel counts and areas include every pixel
// label_pixels gives a region. `dem` is the DEM the mesh was made from, or nullptr for a mesh
// read from a file. Throws terrain::Error (stage "segment") on sizes that do not match,
// labels out of range or unused ids.
// Progress goes to `progress` between its passes over the grid.
RegionGraph region_graph(const TriangleMesh& mesh, const std::vector<float>& field,
                         const std::vector<std::uint32_t>& labels, std::uint32_t region_count,
                         const Dem* dem, const ProgressFn& progress = {});

// The label of each DEM pixel (row-major), 0 where the DEM has NoData; the pixels of a
// collapsed pole row take the pole vertex's label. Every valid pixel has a label: a pixel in
// no triangle (isolated, or touching the others only at a corner) takes, ring by ring
// outwards from the labelled pixels, the most common label among its 8-neighbours labelled
// in an earlier ring (ties: the lowest id); pixels that no ring reaches (no valid 8-path to a
// mesh vertex) form regions of their own, one per 8-connected group, numbered after the
// largest label in `labels` in row-major order of their first pixel.
std::vector<std::uint32_t> label_pixels(const TriangleMesh& mesh, const Dem& dem,
                                        const std::vector<std::uint32_t>& labels,
                                        const ProgressFn& progress = {});

}  // namespace terrain::segment
