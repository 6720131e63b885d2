#pragma once
// Rasters out on a DEM's exact grid (same size, geotransform and CRS), through GDAL.

#include <string>
#include <vector>

#include "terrain/core/dem.hpp"

namespace terrain::io {

// A Float32 GeoTIFF (deflate, tiled) of `pixels` (row-major, grid.width*grid.height), NaN
// for NoData, with the band description `description`. Atomic; refuses to overwrite unless
// asked; throws terrain::Error (stage "write").
void write_float_raster(const Dem& grid, const std::vector<float>& pixels, const std::string& path,
                        bool overwrite, const std::string& description);

}  // namespace terrain::io
