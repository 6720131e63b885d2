#pragma once
// What `segment` and `sweep` share on the command line: their options, turned into the
// pipeline's (terrain/pipeline/segment.hpp, which does the work), and the summary printed.

#include <string>
#include <vector>

#include "cli.hpp"
#include "field_options.hpp"
#include "input.hpp"
#include "terrain/pipeline/segment.hpp"

namespace terrain::cli {

struct SegmentOptionValues {
    reeb::SimplifyOptions simplify;
    std::string min_area;  // --min-area as given, or empty
    segment::GrowOptions grow;
    std::string cost = "auto";
    std::string absorbed = "auto";
    std::string craters = "on";      // --craters on|off
    bool landform_defaults = false;  // no scale option given (no_scale_option)
    std::string format = "GeoJSON";
    bool timings = false;
};

// --persistence, --area-ratio, --min-area, --cost, --saddle-penalty, --absorbed, --format,
// --timings.
void add_segment_options(po::options_description& options, SegmentOptionValues& values);

// Throws UsageError (exit status 2) when both --area-ratio and `area_option` are given.
void check_one_area_threshold(const po::variables_map& vm, const std::string& area_option);

// The pipeline's options from the field options (to_field_options' values) and the segment
// options, their texts parsed (terrain/pipeline/options.hpp); checked before any long work
// (terrain::Error, exit status 1).
pipeline::SegmentOptions to_pipeline_options(const FieldOptionValues& field,
                                             const SegmentOptionValues& values);

// The input's georeference warnings (pipeline::georeference_warnings), one line each on
// stderr: "terrain <command>: warning: ...".
void print_input_warnings(const char* command, const Input& input);
void print_summary(const pipeline::SegmentResult& result, const std::string& output, bool timings);
// The stage table (the paper's Table 2): one line per stage and the total.
void print_timings(const std::vector<pipeline::StageTime>& timings);

}  // namespace terrain::cli
