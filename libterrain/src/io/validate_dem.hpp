#pragma once
// Checks that a raster can describe a surface, before and after its values are read: a
// finite, non-degenerate geotransform with plausible pixel sizes (latitudes inside +-90 on
// a geographic grid), a declared size the file and the memory can back, and finite values
// of plausible magnitude after scale and offset. Each problem is one terrain::Error line.

#include <string>

#include "terrain/core/dem.hpp"
#include "terrain/core/memory_budget.hpp"

class GDALDataset;
class GDALRasterBand;
class OGRSpatialReference;

namespace terrain::io {

// Largest magnitude of an elevation value, in metres (a million kilometres: every body of
// the solar system, the Sun's radius of 696 000 km included, fits).
constexpr double kMaxElevationMagnitude = 1e9;
// Pixel sizes in metres (for grids without a body: any CRS unit converted to metres).
constexpr double kMinPixelMetres = 1e-6;
constexpr double kMaxPixelMetres = 1e9;
// Pixel sizes in degrees for geographic grids.
constexpr double kMinPixelDegrees = 1e-9;

// The grid of `dem` (width, height, transform, body) under `srs` (null: no CRS).
void validate_dem_grid(const std::string& path, const Dem& dem, const OGRSpatialReference* srs);

// After geo::georeference(dem), before the values are read: the body's radius is positive and
// every pixel centre maps to a finite longitude and a latitude inside +-90 (half a pixel of
// slack at the poles), for every kind of CRS. The pixel centres checked are all those of the
// grid's four edges and a lattice of 65 x 65 inside it (on a cylindrical projection, whose
// latitude follows the row, the edges decide); the mesh checks every vertex again. The error
// names where the fault comes from: the PDS3 label's key (`dataset` is the one read; null for
// a grid made in memory) or the geotransform.
void validate_dem_on_body(const std::string& path, const Dem& dem, GDALDataset* dataset);

// After the values are read and the elevation kind is set: the body's radius plus the lowest
// height (or the lowest radius) stays positive.
void validate_dem_heights(const std::string& path, const Dem& dem, GDALDataset* dataset,
                          double min_value);

// The band's declared size against the memory budget (`plan`; null: not checked), and its
// last row read back (a raster whose data end early, such as a PDS label declaring more rows
// than its image holds, is refused before the grid is allocated). The valid pixels are those
// of the whole grid when `all_valid` (no NoData), none otherwise: check_dem_valid_pixels
// checks again once they are counted.
void check_dem_size(const std::string& path, const Dem& dem, GDALRasterBand& band,
                    const MemoryPlan* plan, bool all_valid);

// The plan again with the valid pixels counted (after reading, before the mesh).
void check_dem_valid_pixels(const std::string& path, const Dem& dem, std::size_t valid,
                            const MemoryPlan* plan);

// Scale and offset of the band (before reading).
void validate_scale(const std::string& path, double scale, double offset);

// The range of the valid values after scale and offset.
void validate_value_range(const std::string& path, double min_value, double max_value);

}  // namespace terrain::io
