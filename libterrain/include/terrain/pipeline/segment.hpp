#pragma once
// The segmentation pipeline as library calls (docs/segment.md): the input read and meshed,
// the field, the Reeb graph, its simplification, region growing and the region table, each
// stage timed, with one progress callback; then every output file of `terrain segment` and
// run.json written into a directory. The command line, the examples and the Python module
// call these; the command line adds only option parsing, printing and exit codes.
//
//   auto input = pipeline::load_input("tile.tif");
//   auto result = pipeline::segment(std::move(input), options, progress);
//   pipeline::OutputDirectory dir("out", true);
//   pipeline::write_segment_directory(result, options, "tile.tif", dir.temp_path());
//   dir.commit();

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/pipeline/options.hpp"
#include "terrain/reeb/reeb_graph.hpp"
#include "terrain/reeb/simplify.hpp"
#include "terrain/segment/craters.hpp"
#include "terrain/segment/divide_absorbed.hpp"
#include "terrain/segment/grow_regions.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::pipeline {

// What a pipeline runs on: a DEM and the mesh made from it, or a mesh read from a file.
struct Input {
    std::optional<Dem> dem;  // set for DEM input
    TriangleMesh mesh;
    double read_seconds = 0, mesh_seconds = 0;  // wall time of reading and triangulating
};

struct InputOptions {
    io::ReadDemOptions dem;
    // A DEM's mesh in body-fixed X,Y,Z, or in map easting/northing/height; unset (auto): body
    // for planetary and geographic CRSs, map otherwise (mesh::default_frame).
    std::optional<MeshFrame> frame;
    bool repair = false;  // mesh files: repair degenerate or non-manifold elements
    // The memory plan (pipeline/memory_plan.hpp): the field computed after reading (unset for
    // reading and meshing only) and a limit in bytes (0: none but the memory available).
    // load_input checks the input's declared size against it before reading; it replaces
    // dem.memory.
    std::optional<field::FieldKind> planned_field = field::FieldKind::shape_index;
    std::uint64_t max_memory = 0;
    // The work is pipeline::segment, one scale, which frees and parks what its stages do not
    // read: its own, lower plan (memory_plan's `segment`).
    bool planned_segment = false;
};

// Reads `path` as a mesh file (.off/.ply/.obj) or as a DEM, and meshes the DEM.
Input load_input(const std::string& path, const InputOptions& options = {},
                 const ProgressFn& progress = {});
// A DEM held in memory (georeferenced: geo::georeference(dem) has run), meshed.
Input input_from_dem(Dem dem, std::optional<MeshFrame> frame = std::nullopt,
                     const ProgressFn& progress = {});

// The options of `terrain segment` (docs/cli.md), with its defaults. The command line and the
// Python module read them from text with the parsers of terrain/pipeline/options.hpp.
// The ladder's field made in parts by several processes (MPI ranks; docs/scale.md, "Ranks"):
// this process makes the DEM's rows [rows x part / parts, rows x (part + 1) / parts) (the
// field by bands of rows, docs/field.md), then `gather` fills in the other parts' values and
// scales from theirs. `bounds` holds each part's first vertex and, last, the vertex count: a
// DEM's vertices are numbered by rows, so part p holds [bounds[p], bounds[p + 1]). The field
// is the whole field's bit for bit, so the outputs do not depend on the number of parts.
// Only the ladder's field on a DEM splits (field_splits); other fields are made whole.
struct FieldShare {
    int part = 0, parts = 1;
    std::function<void(std::vector<float>& field, std::vector<std::uint8_t>& scale,
                       const std::vector<std::size_t>& bounds)>
        gather;
    // segment() returns once the field is gathered: a process that takes part in the field
    // only (its result holds the input and the field).
    bool stop_after_field = false;
};

struct SegmentOptions {
    // The shape index, the SDF or the height.
    field::FieldKind field = field::FieldKind::shape_index;
    field::ShapeIndexOptions shape_index;       // rings, radius
    int rays = 25;                              // sdf: rays per face
    double cone_angle_degrees = 120;            // sdf: opening of each face's cone of rays
    bool postprocess = true;                    // sdf: bilateral smoothing of the face values
    bool allow_open = false;                    // sdf: a mesh with holes is accepted
    reeb::SimplifyOptions simplify{10.0, 0.5};  // persistence, area ratio (percent)
    // The area threshold: an area in m^2 (parse_min_area reads "5km2", "2000m2", "3ha", "1e6"),
    // auto (kAutoMinAreaPixels of the mesh's mean vertex area: the DEM's pixel, whatever the
    // extent), or none.
    // When set it replaces simplify.area_ratio: an arc is cancelled when its area on the body
    // is below it, applied as the equivalent ratio 100 * min_area / (the mesh's area) percent
    // (reeb::area_ratio_for_area), so the same landform is kept whatever the tile's extent.
    MinArea min_area;
    // Graph (Reeb-graph constrained) or standard; unset (auto): graph for DEMs, standard for
    // meshes (grow_cost).
    std::optional<segment::GrowCost> cost;
    double saddle_penalty = 20;
    std::string format = "GeoJSON";  // OGR driver of the region polygons
    // What the growing does with the vertices the simplification absorbed into surviving
    // nodes: divide gives them back to the regions around by their own values
    // (segment::divide_absorbed); whole keeps each node one unit, as the paper does; unset
    // (auto, the default): divide on a DEM, whole on a mesh read from a file (where the
    // paper's benchmark scores better so; absorbed_mode).
    std::optional<Absorbed> absorbed;
    // Landforms at their own scale (docs/segment.md, "Landforms at their own scale"): on a DEM
    // with the shape index, the field's radius chosen per vertex (shape_index.auto_scale) and
    // min_area "auto", whatever shape_index and min_area say; a mesh file is left as it is.
    // The command line and the Python module set it when no scale option is given.
    bool landform_defaults = false;
    // DEM input: the craters read from the regions (segment::find_craters; craters.csv and
    // craters.scc, docs/craters.md).
    bool craters = true;
    // Large arrays that wait unread through the Reeb graph and the simplification (the DEM's
    // values, the field, the mesh's pixel maps) are parked in an unlinked temporary file in
    // this directory (empty: $TMPDIR, else /tmp) when they hold park_min_bytes or more; a
    // directory that refuses the file, or a full disk, leaves them in memory. The outputs are
    // the same either way (docs/performance.md, "Arrays parked on disk").
    std::string park_directory;
    std::size_t park_min_bytes = std::size_t{64} << 20;
    FieldShare field_share;
};

// Whether segment() with these options splits the field of this input over
// options.field_share's parts: the ladder's field (shape_index.auto_scale, or the landform
// defaults) on a DEM.
bool field_splits(const SegmentOptions& options, const Input& input);

// The ladder's field of a DEM mesh (field::scale_selected_shape_index) made by `share`'s parts:
// this process's band of rows, then the others' gathered (share.parts 1: made whole).
field::ScaleSelectedField shared_scale_selected_field(const TriangleMesh& mesh,
                                                      field::ShapeIndexOptions options,
                                                      const FieldShare& share,
                                                      const ProgressFn& progress = {});

// The smallest landform of min_area "auto", in mean vertex areas (pixels of a DEM): a floor
// of about 5 pixels across, that of a crater of about 10.
inline constexpr double kAutoMinAreaPixels = 20;
// The options a run takes on this input: landform_defaults applied when `dem`, absorbed set.
SegmentOptions resolve_options(const SegmentOptions& options, bool dem);
// The area threshold in m^2 that options.min_area gives on `mesh` (0 when it is none).
double min_area_m2(const SegmentOptions& options, const TriangleMesh& mesh);

// The thresholds, checked before any long work; throws terrain::Error.
void check_options(const SegmentOptions& options);
// The simplification thresholds applied on `mesh`: options.simplify, with the area ratio
// given by options.min_area when it is set, without the rewritten field (the segmentation
// does not read it).
reeb::SimplifyOptions simplify_options(const SegmentOptions& options, const TriangleMesh& mesh);

// What the caller should tell the user, once, about a DEM's georeference before segmenting
// it (the library never prints): a raster with no geotransform (an image: its pixels are
// taken as squares of the --pixel-size, 1 m by default) or no CRS (the outputs are in
// local map metres, with no longitude/latitude). Empty for a georeferenced DEM.
std::vector<std::string> georeference_warnings(const Dem& dem);
// The field library's options.
field::FieldOptions field_options(const SegmentOptions& options);
// The cost `auto` resolves to: graph for a DEM, standard for a mesh file.
segment::GrowCost grow_cost(const SegmentOptions& options, bool dem);
// The absorbed vertices' mode `auto` resolves to: divide for a DEM, whole for a mesh file.
Absorbed absorbed_mode(const SegmentOptions& options, bool dem);

struct StageTime {
    std::string name;
    double seconds = 0;
};

// The mesh's counts in run.json. Edges come from the adjacency lists; in an edge-manifold
// mesh 3F = 2 E_interior + E_boundary, so E_boundary = 2E - 3F without looking at edges.
struct MeshCounts {
    std::size_t vertices = 0, faces = 0, boundary_edges = 0;
    std::int64_t euler_characteristic = 0;
};
MeshCounts mesh_counts(const TriangleMesh& mesh);

// What the segmentation of one input gives: the field, the labels per mesh vertex, the
// region table and adjacency graph, the counts and the time of each stage.
struct SegmentResult {
    Input input;
    std::vector<float> field;  // per mesh vertex, as computed
    // The shape index's method and window as compute_field took them (run.json), named while
    // the mesh is whole: the mesh's arrays may be freed before run.json is written.
    std::string shape_index_method, shape_index_window;
    std::size_t critical_before = 0;  // critical nodes of the unsimplified Reeb graph
    std::size_t parked_bytes = 0;     // bytes parked on disk at the simplification's peak
    std::size_t parked_most = 0;      // the most bytes parked on disk at once (segment())
    // Bytes parked while the field is computed and while the absorbed vertices are divided
    // (segment()).
    std::size_t parked_field = 0, parked_growing = 0;
    // The parked file's largest length: the most disk the run took at once (segment()).
    std::size_t parked_file = 0;
    reeb::ReebSummary after;  // the simplified graph of the segmentation
    // Its region_count counts every region of the table: on a DEM, after the vertices'
    // regions, those of valid pixels in no triangle (segment::label_pixels).
    segment::Segmentation segmentation;
    segment::DivideCounts divided;  // with absorbed = divide
    segment::RegionGraph regions;
    std::vector<StageTime> timings;         // read, mesh, field, reeb, simplify, grow, write
    std::optional<MeshCounts> mesh_counts;  // kept by release_large_data for run.json
    double area_ratio_percent = 0;          // the area-ratio threshold applied (percent)
    double min_area_m2 = 0;                 // the area threshold applied (m^2), 0 if none
    // With the scale chosen per vertex (shape_index.auto_scale): the ladder of radii
    // (metres) and each vertex's index in it, freed once the region table holds the scale.
    std::vector<double> field_radii;
    double pixel_noise_m = 0;  // --radius auto: the DEM's pixel noise (field::pixel_noise)
    std::vector<std::uint8_t> field_scale;
    std::optional<segment::CraterTable> craters;  // DEM input with SegmentOptions::craters

    const Dem* dem() const { return input.dem ? &*input.dem : nullptr; }
    void add_time(const std::string& name, double seconds);
    // The label of each DEM pixel (row-major, 0 = NoData), as in labels.tif; DEM input only.
    std::vector<std::uint32_t> label_pixels() const;
};

// The field of the input's mesh into result.field (stage "field").
void compute_field(SegmentResult& result, const SegmentOptions& options,
                   const ProgressFn& progress = {});
// The unsimplified Reeb graph of result.field (stage "reeb"); sets critical_before. A DEM
// mesh's triangles are released before it when it is a tree (reeb::reeb_is_tree: the contour
// tree makes the graph from the grid), else after it (TriangleMesh::release_triangles).
reeb::ReebGraph compute_reeb(SegmentResult& result, const ProgressFn& progress = {});

// One scale: the graph simplified with options.simplify and the regions grown on it.
struct ScaleResult {
    segment::Segmentation segmentation;
    segment::DivideCounts divided;  // with absorbed = divide
    reeb::ReebSummary after;        // of the simplified graph
    double simplify_seconds = 0, grow_seconds = 0;
};
// Reads its arguments only, so scales can run side by side.
// The regions grown on a graph already simplified (a sweep's scale, continuing from the
// finer one's graph); `field` is the field before any simplification; `finer`, if given,
// the finer scale's vertex labels (segment::divide_absorbed).
ScaleResult grow_simplified(const Input& input, const std::vector<float>& field,
                            const SegmentOptions& options, const reeb::SimplifyResult& simplified,
                            const std::vector<std::uint32_t>* finer = nullptr,
                            const ProgressFn& progress = {});
// `field` is the field the graph was built on (before any simplification).
ScaleResult segment_scale(const Input& input, const std::vector<float>& field,
                          const reeb::ReebGraph& graph, const SegmentOptions& options,
                          const ProgressFn& progress = {});

// The whole segmentation: field, Reeb graph, simplification, growing, region table.
// Throws terrain::Error (with the failing stage) on bad options or input, "cancelled" when
// the progress callback returns false.
SegmentResult segment(Input input, const SegmentOptions& options, const ProgressFn& progress = {});

// Frees the mesh's arrays, the field and the labels (what is left: counts, timings, the
// region table, the DEM), and gives the memory back to the system.
void release_large_data(SegmentResult& result);

struct WriteOptions {
    // Frees the large data once the files that need it are written, before preview.png is
    // encoded (its frame and PNG buffers then do not add to the peak memory).
    bool release_memory = false;
};

// Every output of `terrain segment` into the existing directory `dir` (docs/outputs.md):
// for a DEM labels.tif, regions.<format>, adjacency.{json,graphml,geojson}, preview.png;
// for a mesh file labels.ply, faces.seg and the adjacency files; then run.json, which
// records `input_path`. Returns the file names written (run.json last). Stage "write".
std::vector<std::string> write_segment_directory(
    SegmentResult& result, const SegmentOptions& options, const std::string& input_path,
    const std::string& dir, const WriteOptions& write = {}, const ProgressFn& progress = {});

// run.json at `path`: the input, parameters, counts, timings, the files written, `extra`
// members (name, JSON text) and the versions.
void write_run_json(const SegmentResult& result, const std::string& input_path,
                    const SegmentOptions& options, const std::vector<std::string>& files,
                    const std::string& path,
                    const std::vector<std::pair<std::string, std::string>>& extra = {});

// A directory written in full beside its final place, then moved there: it appears complete
// or not at all. An existing non-empty directory is refused unless `overwrite`. Throws
// terrain::Error (stage "write") when the place cannot be written.
class OutputDirectory {
  public:
    OutputDirectory(std::string path, bool overwrite);
    ~OutputDirectory();
    OutputDirectory(const OutputDirectory&) = delete;
    OutputDirectory& operator=(const OutputDirectory&) = delete;
    const std::string& temp_path() const { return temp_; }
    void commit();

  private:
    std::string path_, temp_;
    bool committed_ = false;
};

// The library as one call: reads `input_path`, segments it and writes `output_dir` as
// `terrain segment` does. Returns the result with its large data released.
SegmentResult segment_to_directory(const std::string& input_path, const std::string& output_dir,
                                   bool overwrite, const InputOptions& input_options,
                                   const SegmentOptions& options, const ProgressFn& progress = {});

}  // namespace terrain::pipeline
