#pragma once
// labels.tif of a sweep: the labels of several scales in one file (docs/sweep.md). Like every
// writer of io/: atomic, refuses an existing file unless `overwrite`, throws one
// terrain::Error (stage "write") on failure, and writes the same bytes for the same input.

#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {

// One UInt32 band per scale on the DEM's exact grid, NoData 0, each band's description
// saying its scale ("area_ratio=0.5"). `bands`: segment::label_pixels() of each scale.
void write_label_stack(const Dem& dem, const std::vector<std::vector<std::uint32_t>>& bands,
                       const std::vector<std::string>& descriptions, const std::string& path,
                       bool overwrite);
// The same with each band's raster attribute table (`graphs[i]` describes band i; as
// labels.tif's, docs/outputs.md), which GDAL keeps in `path`.aux.xml beside the GeoTIFF, with
// band 1's colour table (entry i the colour of region i, below 65536 regions) there too; and a
// QGIS style, label_style_path(path) (labels.qml), that shows band 1 in the regions' colours.
void write_label_stack(const Dem& dem, const std::vector<std::vector<std::uint32_t>>& bands,
                       const std::vector<std::string>& descriptions,
                       const std::vector<const segment::RegionGraph*>& graphs,
                       const std::string& path, bool overwrite);

}  // namespace terrain::io
