#pragma once
// The files `terrain segment` writes (METHOD.md section 6, docs/outputs.md): a label raster,
// region polygons, the region adjacency graph three ways, a preview picture, and for meshes
// read from files a labelled PLY and a Princeton Segmentation Benchmark face labelling.
// Every writer is atomic (a temporary sibling renamed when complete), refuses an existing
// file unless `overwrite`, throws one terrain::Error (stage "write") on failure, and writes
// the same bytes for the same input.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {

// `pixels`: segment::label_pixels() of the DEM (row-major, 0 = no region).

// labels.tif: UInt32 GeoTIFF on the DEM's exact grid, NoData 0, with a raster attribute
// table (one row per region: its properties and its colour as Red/Green/Blue/Alpha columns)
// that GDAL keeps in `path`.aux.xml beside it (GeoTIFF holds colour tables for 8 and 16-bit
// bands only).
void write_label_raster(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                        const segment::RegionGraph& graph, const std::string& path, bool overwrite);

struct RegionPolygonOptions {
    std::string driver = "GeoJSON";  // or any OGR vector driver that creates files ("GPKG")
    // GeoJSON is always lon/lat (EPSG:4326 on Earth, the body's geographic CRS elsewhere);
    // other drivers keep the DEM's own CRS unless this is set.
    bool lonlat = false;
    std::string layer = "regions";  // the layer's name (drivers other than GeoJSON)
    // Add the layer to `path` if it exists (GPKG with one layer per scale), writing in place:
    // the caller makes the outputs atomic (terrain sweep writes into a temporary directory).
    bool append_layer = false;
};

// regions.geojson: one feature per region (Polygon, MultiPolygon where its pixels touch
// only at corners; null when it has no pixel) made with GDALPolygonize, with the region's
// properties. A DEM without CRS gives its map (geotransform) coordinates.
void write_region_polygons(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                           const segment::RegionGraph& graph, const std::string& path,
                           bool overwrite, const RegionPolygonOptions& options = {});

// The region polygons of one labelling (GDALPolygonize, in the DEM's map coordinates), made
// once to be written to several files: terrain sweep writes each scale to a GeoPackage layer
// and to GeoJSON. Writers copy what they change, so several may read one set at once.
class RegionPolygons {
  public:
    RegionPolygons();
    ~RegionPolygons();
    RegionPolygons(RegionPolygons&&) noexcept;
    RegionPolygons& operator=(RegionPolygons&&) noexcept;
    std::size_t region_count() const;

    struct Impl;
    const Impl& impl() const { return *impl_; }

  private:
    explicit RegionPolygons(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
    friend RegionPolygons polygonize_regions(const Dem&, const std::vector<std::uint32_t>&,
                                             std::size_t);
};
RegionPolygons polygonize_regions(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                                  std::size_t region_count);
// write_region_polygons from polygons made before (for the labelling the graph describes).
void write_region_polygons(const Dem& dem, const RegionPolygons& polygons,
                           const segment::RegionGraph& graph, const std::string& path,
                           bool overwrite, const RegionPolygonOptions& options = {});

// The region colour of labels.tif and the polygons' "fill": deterministic, distinct
// neighbours in the id sequence; id 0 is transparent black. {r, g, b, a}.
std::array<std::uint8_t, 4> region_colour(std::uint32_t id);

// adjacency.json: {"directed": false, "multigraph": false, "graph": {...}, "nodes": [...],
// "edges": [...]} (networkx: node_link_graph(data, edges="edges")).
void write_adjacency_json(const segment::RegionGraph& graph, const std::string& path,
                          bool overwrite);
// adjacency.graphml: the same graph with typed keys (networkx read_graphml, Gephi).
void write_adjacency_graphml(const segment::RegionGraph& graph, const std::string& path,
                             bool overwrite);
// adjacency.geojson: a Point per region at its representative vertex and a LineString per
// edge between the two points, in the graph's point frame.
void write_adjacency_geojson(const segment::RegionGraph& graph, const std::string& path,
                             bool overwrite);

// preview.png: hillshade of the DEM blended with the field's colour map (blue concave, white
// flat, red convex on [0,100]), region boundaries in black, NoData transparent; scaled by an
// integer factor (nearest neighbour) to about 1024 pixels on the long side, or reduced to at
// most 4096. `field_pixels`: field::field_to_pixels() of the DEM.
void write_preview_png(const Dem& dem, const std::vector<float>& field_pixels,
                       const std::vector<std::uint32_t>& pixels, const std::string& path,
                       bool overwrite);

// The preview in two steps: its pixels (8-bit RGBA, row-major), then the PNG. Writing goes
// through OpenImageIO, loaded on first use (about 120 MB resident, a quarter of a second): a
// program low on memory renders first, frees its large data, then writes.
struct PreviewImage {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgba;
};
PreviewImage render_preview(const Dem& dem, const std::vector<float>& field_pixels,
                            const std::vector<std::uint32_t>& pixels);
void write_preview_image(const PreviewImage& image, const std::string& path, bool overwrite);

// labels.ply: io::write_ply's mesh with per-vertex `uint label` and `float <field_name>`.
void write_labels_ply(const TriangleMesh& mesh, const std::vector<float>& field,
                      const std::vector<std::uint32_t>& labels, const std::string& path,
                      bool overwrite, const std::string& field_name = "field");

// faces.seg: one region id per face, one per line, in face order (Princeton Segmentation
// Benchmark); a face takes the label most of its vertices have, ties to the lowest.
void write_faces_seg(const TriangleMesh& mesh, const std::vector<std::uint32_t>& labels,
                     const std::string& path, bool overwrite);
// The labels write_faces_seg writes.
std::vector<std::uint32_t> face_labels(const TriangleMesh& mesh,
                                       const std::vector<std::uint32_t>& labels);

// labels.tif of a sweep: one UInt32 band per scale on the DEM's exact grid, NoData 0, each
// band's description saying its scale ("area_ratio=0.5").
void write_label_stack(const Dem& dem, const std::vector<std::vector<std::uint32_t>>& bands,
                       const std::vector<std::string>& descriptions, const std::string& path,
                       bool overwrite);

// sweep.png: region count (blue) and mean region area (red) against the area ratio (log
// scale), each on its own axis from 0 to its maximum.
void write_sweep_plot(const std::vector<double>& area_ratios,
                      const std::vector<double>& region_counts,
                      const std::vector<double>& mean_areas, const std::string& path,
                      bool overwrite);

struct SegmentOutputOptions {
    bool overwrite = false;
    RegionPolygonOptions polygons;     // regions.<extension of the driver>
    std::string field_name = "field";  // the field's name in labels.ply
    // When set, preview.png is rendered into *deferred_preview instead of written; the caller
    // writes it with write_preview_image (to the path returned for it) once it has freed what
    // it no longer needs.
    PreviewImage* deferred_preview = nullptr;
};

// Everything for one segmentation into the existing directory `dir`: for a DEM (dem !=
// nullptr) labels.tif, regions.geojson, adjacency.{json,graphml,geojson}, preview.png; for a
// mesh read from a file labels.ply, faces.seg and the three adjacency files. Every path is
// checked before anything is written. Returns the paths written, in that order.
std::vector<std::string> write_segment_outputs(const std::string& dir, const TriangleMesh& mesh,
                                               const std::vector<float>& field,
                                               const std::vector<std::uint32_t>& labels,
                                               const segment::RegionGraph& graph, const Dem* dem,
                                               const SegmentOutputOptions& options = {},
                                               const ProgressFn& progress = {});

}  // namespace terrain::io
