#pragma once
// Reads one band of any raster GDAL opens into a terrain::Dem.

#include <optional>
#include <string>

#include "terrain/core/dem.hpp"
#include "terrain/core/memory_budget.hpp"
#include "terrain/core/progress.hpp"

namespace terrain::io {

struct ReadDemOptions {
    int band = 1;                            // 1-based, as in GDAL
    std::optional<ElevationKind> elevation;  // unset: detect (docs/bodies-and-elevation.md)
    bool nan_as_nodata = false;              // NaN/Inf pixels become holes instead of an error
    std::optional<double> pixel_size;        // metres per pixel for rasters with no geotransform
    // The peak of the work planned on the grid (by default the grid alone), checked against
    // the memory budget (terrain/core/memory_budget.hpp) before the pixels are read.
    MemoryPlan memory;
};

// Scale and offset of the band are applied; NoData (and the band's mask) become NaN.
// Throws terrain::Error (stage "read") when the file is missing or not a raster, the band
// does not exist, no pixel is valid, fewer than 2x2 pixels exist, or a valid pixel is not
// finite (unless nan_as_nodata).
Dem read_dem(const std::string& path, const ReadDemOptions& options = {},
             const ProgressFn& progress = {});

// The valid values of a DEM: their range (scale and offset applied) and count.
struct DemValueSummary {
    double min_value = 0, max_value = 0;
    std::size_t valid_pixels = 0;
};
// read_dem without keeping the values: the grid, CRS and body as read_dem gives them (with
// Dem::values empty) and `summary` of the values, read one row at a time (for describing a
// large or sparse raster in the memory of one row).
Dem read_dem_summary(const std::string& path, DemValueSummary& summary,
                     const ReadDemOptions& options = {}, const ProgressFn& progress = {});

// For a grid made in memory (values set, geo::georeference(dem) called, the elevation kind
// set): the checks read_dem makes on the grids it reads that the grid lies on its body: a
// positive radius, every pixel centre's latitude inside +-90 (half a pixel of slack), and the
// body's radius plus the lowest height positive. Throws terrain::Error (stage "read") naming
// the geotransform or the CRS. No-op for a grid without CRS.
void check_dem_on_body(const Dem& dem);

// The radius/height decision of docs/bodies-and-elevation.md for valid values in
// [min_value, max_value] on `body`.
ElevationKind detect_elevation_kind(const Body& body, double min_value, double max_value);

}  // namespace terrain::io
