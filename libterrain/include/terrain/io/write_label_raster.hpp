#pragma once
// labels.tif: the regions of one segmentation on the DEM's grid (docs/outputs.md). Like every
// writer of io/: atomic (a temporary sibling renamed when complete), refuses an existing file
// unless `overwrite`, throws one terrain::Error (stage "write") on failure, and writes the
// same bytes for the same input.

#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {

// `pixels`: segment::label_pixels() of the DEM (row-major, 0 = no region). A UInt32 GeoTIFF
// on the DEM's exact grid, NoData 0, with a raster attribute table (one row per region: its
// properties and its colour, io::region_colour, as Red/Green/Blue/Alpha columns) that GDAL
// keeps in `path`.aux.xml beside it (GeoTIFF holds colour tables for 8 and 16-bit bands only).
void write_label_raster(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                        const segment::RegionGraph& graph, const std::string& path, bool overwrite);

}  // namespace terrain::io
