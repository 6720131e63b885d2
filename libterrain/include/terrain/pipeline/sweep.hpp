#pragma once
// The multi-scale sweep as library calls (docs/sweep.md): the field and the unsimplified
// Reeb graph computed once, one segmentation per area ratio side by side on the cores, the
// lineage of the regions from each scale to the next; then the outputs of `terrain sweep`
// written into a directory.

#include <cstdint>
#include <string>
#include <vector>

#include "terrain/pipeline/segment.hpp"
#include "terrain/segment/lineage.hpp"

namespace terrain::pipeline {

// The lists of scales as text (--area-ratios, --min-areas): parse_area_ratios and
// parse_min_areas, terrain/pipeline/options.hpp.

struct SweepScale {
    double ratio = 0;  // the area-ratio threshold applied (percent)
    // The scale as written in file names and band descriptions: the ratio ("0.25") or, for a
    // sweep over areas, the area as given ("5km2").
    std::string name;
    double min_area_m2 = 0;  // a sweep over areas: the area threshold; 0 otherwise
    segment::Segmentation segmentation;
    reeb::ReebSummary after;  // of its simplified graph
    segment::RegionGraph regions;
    double seconds = 0;
};

struct SweepResult {
    // The input, the field, the critical nodes before simplification and the timings (read,
    // mesh, field, reeb, scales, write). Its segmentation has no labels; write_sweep_directory
    // gives it the counts of the last scale for run.json.
    SegmentResult base;
    std::vector<SweepScale> scales;  // by increasing area ratio
    // lineage[i]: how each region of scale i overlaps the regions of scale i + 1.
    std::vector<std::vector<segment::RegionLineage>> lineage;
};

// One segmentation per area ratio (options.simplify.area_ratio is ignored), from the same
// field and unsimplified Reeb graph. Throws terrain::Error as segment() does, and (stage
// "sweep") for an empty or out-of-range list of ratios.
SweepResult sweep(Input input, const std::vector<double>& area_ratios,
                  const SegmentOptions& options, const ProgressFn& progress = {});
// The same over area thresholds on the body (SegmentOptions::min_area, which is ignored
// here): each becomes the equivalent area ratio on the input's mesh. Scales are named by the
// areas as given.
SweepResult sweep(Input input, const std::vector<AreaThreshold>& min_areas,
                  const SegmentOptions& options, const ProgressFn& progress = {});

// Every output of `terrain sweep` into the existing directory `dir`: labels.tif (one band
// per scale), regions.gpkg and regions_<ratio>.geojson (DEM) or faces_<ratio>.seg (mesh),
// adjacency_<ratio>.json, lineage.json, sweep.csv, sweep.png and run.json. Returns the file
// names written.
std::vector<std::string> write_sweep_directory(SweepResult& result, const SegmentOptions& options,
                                               const std::string& input_path,
                                               const std::string& dir,
                                               const ProgressFn& progress = {});

}  // namespace terrain::pipeline
