#pragma once
// Private: what the label rasters (write_label_raster.cpp, write_label_stack.cpp) share: a
// GDAL colour table and a QGIS style, both with io::region_colour, and the Cloud-Optimized
// GeoTIFF writer. Not installed.

#include <gdal_priv.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "gdal_support.hpp"
#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {

// Entry i is the colour of region i (0 transparent black), for ids 0..region_count.
GDALColorTable region_colour_table(std::size_t region_count);

// A QGIS layer style: the paletted renderer of band `band`, one entry per region in its colour,
// labelled "<id> <landform>"; QGIS loads <name>.qml with <name>.tif.
void write_label_style(std::ostream& out, const segment::RegionGraph& graph, int band = 1);

// A GDAL MEM dataset of the grid's size whose UInt32 bands are `bands` themselves (no copy;
// they must outlive it), georeferenced as the grid.
std::unique_ptr<GDALDataset> labels_in_place(
    const Dem& dem, const std::vector<const std::vector<std::uint32_t>*>& bands,
    const std::string& path, const GdalErrorCapture& errors);

// `source` written at `temp_path` by GDAL's COG driver: 256 x 256 DEFLATE tiles (horizontal
// predictor), overviews down to about 64 pixels (nearest: every overview pixel is one region's
// id), the directories first and the smallest overview's tiles before the larger ones',
// BigTIFF when needed. Returns the file opened (read-only: what is set on it goes to its
// .aux.xml). GDAL's progress goes to `progress` ("write", 0 to 1); a callback that cancels
// stops the copy and its error is thrown.
std::unique_ptr<GDALDataset> write_cloud_optimized(const Dem& dem, GDALDataset& source,
                                                   const std::string& temp_path,
                                                   const std::string& path,
                                                   const GdalErrorCapture& errors,
                                                   const ProgressFn& progress = {});

}  // namespace terrain::io
