#pragma once
// labels.tif: the regions of one segmentation on the DEM's grid (docs/outputs.md). Like every
// writer of io/: atomic (a temporary sibling renamed when complete), refuses an existing file
// unless `overwrite`, throws one terrain::Error (stage "write") on failure, and writes the
// same bytes for the same input.

#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {

// `pixels`: segment::label_pixels() of the DEM (row-major, 0 = no region). A GeoTIFF on the
// DEM's exact grid, NoData 0: UInt16 with a colour table (entry i the colour of region i,
// io::region_colour) below 65536 regions, UInt32 beyond (GeoTIFF holds colour tables for 8
// and 16-bit bands only); internal overviews (nearest) down to 64 pixels on the long side; a
// raster attribute table (one row per region: its properties and its colour as
// Red/Green/Blue/Alpha columns) that GDAL keeps in `path`.aux.xml beside it (GeoTIFF has no
// attribute tables); and a QGIS style, label_style_path(path), with the region colours.
// `progress`: GDAL's writing of the tiles and overviews ("write", 0 to 1); a callback that
// cancels stops it with terrain::Error and leaves no file.
void write_label_raster(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                        const segment::RegionGraph& graph, const std::string& path, bool overwrite,
                        const ProgressFn& progress = {});
// The QGIS style beside a label raster: `path` with the extension .qml (labels.qml).
std::string label_style_path(const std::string& path);

}  // namespace terrain::io
