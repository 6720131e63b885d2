#pragma once
// The field options shared by `field`, `reeb`, `segment` and `sweep`.

#include <string>

#include "cli.hpp"
#include "terrain/field/vertex_field.hpp"

namespace terrain::cli {

struct FieldOptionValues {
    std::string name = "shape-index";
    std::string window = "disk";      // --window
    double cone_angle_degrees = 120;  // --cone-angle (the library takes radians)
    bool no_postprocess = false;
    std::string radius;  // --radius as given: metres, or "auto"
    std::string radii;   // --radii as given: metres, comma-separated
    field::FieldOptions options;
};

// True when none of the options that set a scale was given (--rings, --radius, --radii,
// --persistence, --area-ratio, --min-area, --area-ratios, --min-areas): a DEM then takes the
// landform defaults (pipeline::SegmentOptions::landform_defaults).
bool no_scale_option(const po::variables_map& vm);

// Adds --field, --rings, --radius, --window and the SDF's --rays, --cone-angle, --no-postprocess,
// --allow-open bound to `values`.
void add_field_options(po::options_description& options, FieldOptionValues& values);

// Documented ranges of --rings, --rays and --radius (in mean edge lengths of the mesh).
constexpr int kMaxRings = 10;
constexpr int kMaxRays = 1000;
constexpr double kMaxRadiusEdges = 20;

// The library's options from the parsed values; throws UsageError for contradictions.
field::FieldOptions to_field_options(const FieldOptionValues& values, const po::variables_map& vm);

// Throws terrain::Error when --radius exceeds kMaxRadiusEdges mean edge lengths of `mesh`
// with a window whose cost grows with the radius (the ball, or a mesh read from a file); the
// disk window on a DEM costs the same at any radius and takes any.
void check_field_limits(const field::FieldOptions& options, const TriangleMesh& mesh);

}  // namespace terrain::cli
