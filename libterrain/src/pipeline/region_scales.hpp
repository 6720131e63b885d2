#pragma once
// Private: the regions' scales, set in the region table and written to run.json.

#include <vector>

#include "terrain/core/json_writer.hpp"
#include "terrain/pipeline/segment.hpp"

namespace terrain::pipeline::internal {

// Each region's field scale: the ladder's radius most of its vertices took (ties to the
// smaller), then the per-vertex scales are freed.
void set_region_scales(SegmentResult& result);

// Each region's range of area thresholds: from the segmentation's own to the one at which it
// ends (`to`, by region, segment::seed_area_ranges; the regions of pixels in no triangle have
// no seed).
void set_area_ranges(SegmentResult& result, const std::vector<double>& to);

// run.json's `area_range`: the ladder of area thresholds the ranges were measured on and how
// many regions stand at each.
void write_area_range(JsonWriter& j, const SegmentResult& result);

}  // namespace terrain::pipeline::internal
