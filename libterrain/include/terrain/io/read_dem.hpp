#pragma once
// Reads one band of any raster GDAL opens into a terrain::Dem.

#include <optional>
#include <string>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"

namespace terrain::io {

struct ReadDemOptions {
    int band = 1;                            // 1-based, as in GDAL
    std::optional<ElevationKind> elevation;  // unset: detect (docs/bodies-and-elevation.md)
    bool nan_as_nodata = false;              // NaN/Inf pixels become holes instead of an error
    std::optional<double> pixel_size;        // metres per pixel for rasters with no geotransform
};

// Scale and offset of the band are applied; NoData (and the band's mask) become NaN.
// Throws terrain::Error (stage "read") when the file is missing or not a raster, the band
// does not exist, no pixel is valid, fewer than 2x2 pixels exist, or a valid pixel is not
// finite (unless nan_as_nodata).
Dem read_dem(const std::string& path, const ReadDemOptions& options = {},
             const ProgressFn& progress = {});

// The radius/height decision of docs/bodies-and-elevation.md for valid values in
// [min_value, max_value] on `body`.
ElevationKind detect_elevation_kind(const Body& body, double min_value, double max_value);

}  // namespace terrain::io
