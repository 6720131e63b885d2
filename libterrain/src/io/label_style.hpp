#pragma once
// Private: the colours of label rasters (write_label_raster.cpp, write_label_stack.cpp): a
// GDAL colour table and a QGIS style, both with io::region_colour. Not installed.

#include <gdal_priv.h>

#include <cstddef>
#include <ostream>

#include "terrain/segment/regions.hpp"

namespace terrain::io {

// Entry i is the colour of region i (0 transparent black), for ids 0..region_count.
GDALColorTable region_colour_table(std::size_t region_count);

// A QGIS layer style: the paletted renderer of band `band`, one entry per region in its colour,
// labelled "<id> <landform>"; QGIS loads <name>.qml with <name>.tif.
void write_label_style(std::ostream& out, const segment::RegionGraph& graph, int band = 1);

}  // namespace terrain::io
