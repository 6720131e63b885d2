#pragma once
// Private: the QGIS styles of the region polygons (polygon_style.cpp): each region in its
// colour, or each landform class in its colour, and the GeoPackage table QGIS reads a layer's
// styles from. Not installed.
#include <gdal_priv.h>

#include <string>

#include "gdal_support.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {

// Each region filled with its colour (io::region_colour, the "fill" property), labelled
// "<id> <landform>": the layer's default style.
std::string polygon_style_qml(const segment::RegionGraph& graph);

// Regions filled by their landform class (io::landform_colour), one category per class: a
// map of landforms, the outlines keeping neighbours of one class apart.
std::string landform_style_qml();

// A GeoPackage's layer_styles row for `layer` (the table QGIS reads a layer's default style
// from, created as QGIS does when missing), with a fixed time so the bytes repeat.
void add_layer_style(GDALDataset& ds, const std::string& layer, const std::string& style_name,
                     bool as_default, const std::string& description, const std::string& qml,
                     const std::string& path, const GdalErrorCapture& errors);

}  // namespace terrain::io
