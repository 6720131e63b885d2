// The QGIS styles of the region polygons (docs/outputs.md): categorized renderers in
// QML, and the GeoPackage's layer_styles table that holds them.
#include "polygon_style.hpp"

#include <ogrsf_frmts.h>

#include <array>
#include <cstdint>
#include <sstream>
#include <utility>
#include <vector>

#include "terrain/core/error.hpp"
#include "terrain/io/region_colour.hpp"

namespace terrain::io {
namespace {

// A QGIS fill symbol `name` in colour c, with a thin black outline (regions of one colour
// stay apart).
void fill_symbol(std::ostream& qml, const std::string& name, const std::array<std::uint8_t, 3>& c) {
    qml << "   <symbol type=\"fill\" name=\"" << name
        << "\" alpha=\"1\" clip_to_extent=\"1\" force_rhr=\"0\">\n"
           "    <layer class=\"SimpleFill\" enabled=\"1\" locked=\"0\" pass=\"0\">\n"
           "     <Option type=\"Map\">\n"
           "      <Option name=\"color\" type=\"QString\" value=\""
        << int(c[0]) << ',' << int(c[1]) << ',' << int(c[2]) << ",255\"/>\n"
        << "      <Option name=\"outline_color\" type=\"QString\" value=\"0,0,0,255\"/>\n"
           "      <Option name=\"outline_width\" type=\"QString\" value=\"0.1\"/>\n"
           "      <Option name=\"style\" type=\"QString\" value=\"solid\"/>\n"
           "     </Option>\n    </layer>\n   </symbol>\n";
}

// A QGIS style for the polygons: a categorized renderer on `attribute`, one category per
// (value, label, colour).
struct Category {
    std::string value, label;
    std::array<std::uint8_t, 3> colour;
};
std::string categorized_style_qml(const std::string& attribute,
                                  const std::vector<Category>& categories) {
    std::ostringstream qml;
    qml << "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n"
           "<qgis version=\"3.22.0\" styleCategories=\"Symbology\">\n"
           " <renderer-v2 type=\"categorizedSymbol\" attr=\""
        << attribute
        << "\" symbollevels=\"0\" "
           "enableorderby=\"0\" forceraster=\"0\">\n  <categories>\n";
    for (std::size_t i = 0; i < categories.size(); ++i)
        qml << "   <category value=\"" << categories[i].value << "\" symbol=\"" << i
            << "\" label=\"" << categories[i].label << "\" render=\"true\"/>\n";
    qml << "  </categories>\n  <symbols>\n";
    for (std::size_t i = 0; i < categories.size(); ++i)
        fill_symbol(qml, std::to_string(i), categories[i].colour);
    qml << "  </symbols>\n </renderer-v2>\n</qgis>\n";
    return qml.str();
}

}  // namespace

// Each region filled with its colour (io::region_colour, the "fill" property), labelled
// "<id> <landform>": the layer's default style.
std::string polygon_style_qml(const segment::RegionGraph& graph) {
    std::vector<Category> categories;
    for (const auto& r : graph.regions) {
        const auto c = region_colour(r.id);
        categories.push_back({std::to_string(r.id),
                              std::to_string(r.id) + ' ' + segment::to_string(r.landform),
                              {c[0], c[1], c[2]}});
    }
    return categorized_style_qml("id", categories);
}

// Regions filled by their landform class (io::landform_colour), one category per class: a
// map of landforms, the outlines keeping neighbours of one class apart.
std::string landform_style_qml() {
    std::vector<Category> categories;
    for (int k = 0; k <= static_cast<int>(segment::Landform::unknown); ++k) {
        const auto landform = static_cast<segment::Landform>(k);
        const std::string name = segment::to_string(landform);
        categories.push_back({name, name, landform_colour(landform)});
    }
    return categorized_style_qml("landform", categories);
}

// A GeoPackage's layer_styles row for `layer` (the table QGIS reads a layer's default style
// from, created as QGIS does when missing), with a fixed time so the bytes repeat.
void add_layer_style(GDALDataset& ds, const std::string& layer, const std::string& style_name,
                     bool as_default, const std::string& description, const std::string& qml,
                     const std::string& path, const GdalErrorCapture& errors) {
    OGRLayer* styles = ds.GetLayerByName("layer_styles");
    if (!styles) {
        styles = ds.CreateLayer("layer_styles", nullptr, wkbNone, nullptr);
        if (!styles)
            throw Error("write", "cannot create layer_styles in '" + path + "'" + errors.suffix());
        const std::pair<const char*, OGRFieldType> fields[] = {{"f_table_catalog", OFTString},
                                                               {"f_table_schema", OFTString},
                                                               {"f_table_name", OFTString},
                                                               {"f_geometry_column", OFTString},
                                                               {"styleName", OFTString},
                                                               {"styleQML", OFTString},
                                                               {"styleSLD", OFTString},
                                                               {"useAsDefault", OFTInteger},
                                                               {"description", OFTString},
                                                               {"owner", OFTString},
                                                               {"ui", OFTString},
                                                               {"update_time", OFTDateTime}};
        for (const auto& [name, type] : fields) {
            OGRFieldDefn field(name, type);
            if (std::string(name) == "useAsDefault") field.SetSubType(OFSTBoolean);
            if (styles->CreateField(&field) != OGRERR_NONE)
                throw Error("write",
                            "cannot create layer_styles in '" + path + "'" + errors.suffix());
        }
    }
    OGRFeature row(styles->GetLayerDefn());
    row.SetField("f_table_catalog", "");
    row.SetField("f_table_schema", "");
    row.SetField("f_table_name", layer.c_str());
    row.SetField("f_geometry_column", "geom");
    row.SetField("styleName", style_name.c_str());
    row.SetField("styleQML", qml.c_str());
    row.SetField("styleSLD", "");
    row.SetField("useAsDefault", as_default ? 1 : 0);
    row.SetField("description", description.c_str());
    row.SetField("owner", "");
    row.SetField("ui", "");
    row.SetField("update_time", 2000, 1, 1, 0, 0, 0.0f, 100);
    if (styles->CreateFeature(&row) != OGRERR_NONE)
        throw Error("write", "cannot write the style of '" + path + "'" + errors.suffix());
}

}  // namespace terrain::io
