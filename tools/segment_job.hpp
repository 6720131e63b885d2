#pragma once
// The steps `segment` and `sweep` share: options, the field and Reeb graph computed once,
// one segmentation per area ratio, the output files, run.json, and the atomic output
// directory.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "field_options.hpp"
#include "input.hpp"
#include "terrain/io/write_preview.hpp"
#include "terrain/reeb/simplify.hpp"
#include "terrain/segment/grow_regions.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::cli {

struct SegmentOptionValues {
    reeb::SimplifyOptions simplify;
    segment::GrowOptions grow;
    std::string cost = "auto";
    std::string format = "GeoJSON";
    bool timings = false;
};

// --persistence, --area-ratio, --cost, --saddle-penalty, --format, --timings.
void add_segment_options(po::options_description& options, SegmentOptionValues& values);
// Thresholds and names checked before any long work (terrain::Error, exit status 1).
void check_segment_options(const SegmentOptionValues& values);

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

struct SegmentJob {
    Input input;
    std::vector<float> field;  // as computed
    reeb::ReebGraph graph;     // before simplification
    std::size_t critical_before = 0;
    reeb::ReebSummary after;  // the simplified graph of the segmentation below
    segment::Segmentation segmentation;
    segment::RegionGraph regions;
    std::vector<StageTime> timings;
    std::optional<MeshCounts> mesh_counts;  // kept by release_large_data for run.json
    const Dem* dem() const { return input.dem ? &*input.dem : nullptr; }
    void add_time(const std::string& name, double seconds);
};

void compute_field(SegmentJob& job, const field::FieldOptions& options, const ProgressFn& progress);
void compute_reeb(SegmentJob& job, const ProgressFn& progress);
struct ScaleResult {
    segment::Segmentation segmentation;
    reeb::ReebSummary after;  // of the simplified graph
    double simplify_seconds = 0, grow_seconds = 0;
};
// Simplifies job.graph with values.simplify and grows the regions (cost auto: graph for DEMs,
// standard for meshes). Reads the job only, so scales can run side by side.
ScaleResult segment_scale(const SegmentJob& job, const SegmentOptionValues& values,
                          const ProgressFn& progress = {});
// segment_scale into the job (segmentation, after, timings); takes job.graph, which is
// empty afterwards.
void segment_once(SegmentJob& job, const SegmentOptionValues& values, const ProgressFn& progress);
// Every output of one segmentation into `dir`; returns the file names written. With
// `deferred_preview`, preview.png is only rendered, for write_deferred_preview.
std::vector<std::string> write_segmentation(SegmentJob& job, const SegmentOptionValues& values,
                                            const std::string& dir, const ProgressFn& progress,
                                            io::PreviewImage* deferred_preview = nullptr);
// Frees the mesh's arrays, the field, the graph and the labels (what is left: counts, timings,
// the mesh's topology and frame, the DEM), and gives the memory back to the system.
void release_large_data(SegmentJob& job);
// Writes the preview rendered by write_segmentation into dir/preview.png, timed as "write":
// loading OpenImageIO for it then does not add to the job's peak memory.
void write_deferred_preview(SegmentJob& job, const io::PreviewImage& preview,
                            const std::string& dir);
void write_run_json(const SegmentJob& job, const std::string& input_path,
                    const FieldOptionValues& field, const SegmentOptionValues& values,
                    const std::vector<std::string>& files, const std::string& path,
                    const std::vector<std::pair<std::string, std::string>>& extra = {});
void print_summary(const SegmentJob& job, const std::string& output, bool timings);
// The stage table (the paper's Table 2): one line per stage and the total.
void print_timings(const std::vector<StageTime>& timings);

// A directory written in full beside its final place, then moved there: OUTDIR appears
// complete or not at all. An existing non-empty OUTDIR is refused unless overwrite.
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

}  // namespace terrain::cli
