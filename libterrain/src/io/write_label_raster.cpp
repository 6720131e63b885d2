#include <gdal_priv.h>
#include <gdal_rat.h>
#include <ogr_spatialref.h>
#include <vrtdataset.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <ostream>
#include <variant>

#include "dataset_files.hpp"
#include "gdal_support.hpp"
#include "label_style.hpp"
#include "region_attributes.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/region_colour.hpp"
#include "terrain/io/write_label_raster.hpp"

namespace terrain::io {
namespace {}  // namespace

// One row per region: its attributes (but "fill") and its colour. Thematic, with the id as
// the value column, so GDAL and QGIS map pixel values to rows.
GDALDefaultRasterAttributeTable region_attribute_table(const segment::RegionGraph& graph) {
    GDALDefaultRasterAttributeTable rat;
    rat.SetTableType(GRTT_THEMATIC);
    rat.SetRowCount(static_cast<int>(graph.regions.size()));
    for (std::size_t row = 0; row < graph.regions.size(); ++row) {
        const auto attributes = region_attributes(graph, graph.regions[row]);
        int col = 0;
        for (const auto& [name, value] : attributes) {
            if (name == "fill") continue;
            if (row == 0) {
                const GDALRATFieldType type =
                    std::holds_alternative<std::int64_t>(value)
                        ? GFT_Integer
                        : (std::holds_alternative<double>(value) ? GFT_Real : GFT_String);
                const GDALRATFieldUsage usage =
                    name == "id"
                        ? GFU_MinMax
                        : (name == "pixel_count" ? GFU_PixelCount
                                                 : (name == "landform" ? GFU_Name : GFU_Generic));
                rat.CreateColumn(name.c_str(), type, usage);
            }
            const int r = static_cast<int>(row);
            if (const auto* i = std::get_if<std::int64_t>(&value))
                rat.SetValue(r, col, static_cast<int>(*i));
            else if (const auto* d = std::get_if<double>(&value))
                rat.SetValue(r, col, *d);
            else
                rat.SetValue(r, col, std::get<std::string>(value).c_str());
            ++col;
        }
        const auto colour = region_colour(graph.regions[row].id);
        const char* names[] = {"Red", "Green", "Blue", "Alpha"};
        const GDALRATFieldUsage usages[] = {GFU_Red, GFU_Green, GFU_Blue, GFU_Alpha};
        for (int k = 0; k < 4; ++k) {
            if (row == 0) rat.CreateColumn(names[k], GFT_Integer, usages[k]);
            rat.SetValue(static_cast<int>(row), col++, int(colour[std::size_t(k)]));
        }
    }
    return rat;
}

GDALColorTable region_colour_table(std::size_t region_count) {
    GDALColorTable table(GPI_RGB);
    for (std::size_t id = 0; id <= region_count; ++id) {
        const auto c = region_colour(static_cast<std::uint32_t>(id));
        const GDALColorEntry entry{c[0], c[1], c[2], c[3]};
        table.SetColorEntry(static_cast<int>(id), &entry);
    }
    return table;
}

namespace {

// Overview factors 2, 4, 8, ... while the reduced grid keeps 64 pixels on its long side.
std::vector<int> overview_factors(const Dem& dem) {
    std::vector<int> factors;
    const int longest = std::max(dem.width, dem.height);
    for (int f = 2; longest / f >= 64; f *= 2) factors.push_back(f);
    return factors;
}

std::string hex_colour(const std::array<std::uint8_t, 4>& c) {
    char text[8];
    std::snprintf(text, sizeof text, "#%02x%02x%02x", c[0], c[1], c[2]);
    return text;
}

std::string xml_escape(const std::string& s) {
    std::string out;
    for (const char ch : s) {
        switch (ch) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += ch;
        }
    }
    return out;
}

}  // namespace

void write_label_style(std::ostream& out, const segment::RegionGraph& graph, int band) {
    out << "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n"
           "<qgis version=\"3.22.0\" styleCategories=\"Symbology\">\n"
           " <pipe>\n"
           "  <rasterrenderer type=\"paletted\" band=\""
        << band
        << "\" opacity=\"1\" "
           "alphaBand=\"-1\" nodataColor=\"\">\n"
           "   <rasterTransparency/>\n"
           "   <colorPalette>\n";
    for (const auto& region : graph.regions) {
        const auto c = region_colour(region.id);
        out << "    <paletteEntry value=\"" << region.id << "\" color=\"" << hex_colour(c)
            << "\" alpha=\"" << int(c[3]) << "\" label=\""
            << xml_escape(std::to_string(region.id) + " " + segment::to_string(region.landform))
            << "\"/>\n";
    }
    out << "   </colorPalette>\n"
           "  </rasterrenderer>\n"
           " </pipe>\n"
           "</qgis>\n";
}

std::string label_style_path(const std::string& path) {
    return std::filesystem::path(path).replace_extension(".qml").string();
}

std::unique_ptr<GDALDataset> labels_in_place(
    const Dem& dem, const std::vector<const std::vector<std::uint32_t>*>& bands,
    const std::string& path, const GdalErrorCapture& errors) {
    std::unique_ptr<GDALDataset> mem(GetGDALDriverManager()->GetDriverByName("MEM")->Create(
        "", dem.width, dem.height, 0, GDT_UInt32, nullptr));
    if (!mem) throw Error("write", "cannot create '" + path + "'" + errors.suffix());
    for (const auto* values : bands)
        if (!add_band_in_place(*mem, GDT_UInt32, values->data(), sizeof(std::uint32_t),
                               sizeof(std::uint32_t) * std::size_t(dem.width)))
            throw Error("write", "cannot create '" + path + "'" + errors.suffix());
    set_grid_georeference(*mem, dem, true);
    return mem;
}

std::unique_ptr<GDALDataset> write_cloud_optimized(const Dem& dem, GDALDataset& source,
                                                   const std::string& temp_path,
                                                   const std::string& path,
                                                   const GdalErrorCapture& errors,
                                                   const ProgressFn& progress) {
    const auto factors = overview_factors(dem);
    CPLStringList options;
    options.SetNameValue("COMPRESS", "DEFLATE");
    options.SetNameValue("PREDICTOR", "YES");
    options.SetNameValue("BLOCKSIZE", "256");
    options.SetNameValue("BIGTIFF", "IF_SAFER");
    options.SetNameValue("RESAMPLING", "NEAREST");
    if (factors.empty())
        options.SetNameValue("OVERVIEWS", "NONE");
    else
        options.SetNameValue("OVERVIEW_COUNT", std::to_string(factors.size()).c_str());
    GDALDriver* cog = GetGDALDriverManager()->GetDriverByName("COG");
    if (!cog) throw Error("write", "GDAL has no COG driver (GDAL 3.1 or later is needed)");
    // A paletted band's colour table stays in the full grid's directory: a UInt16 TIFF colour
    // table is 65 536 entries (384 KB), which the overviews' directories would repeat, while
    // their pixels are ids whose colours the full grid's table (and labels.qml) give. (Set for
    // this thread only: the other outputs are written beside it.)
    const bool paletted =
        source.GetRasterCount() > 0 && source.GetRasterBand(1)->GetColorTable() != nullptr;
    const CPLConfigOptionSetter plain_overviews("PHOTOMETRIC_OVERVIEW",
                                                paletted ? "MINISBLACK" : nullptr, false);
    GdalProgress reported{progress};
    std::unique_ptr<GDALDataset> ds(cog->CreateCopy(temp_path.c_str(), &source, FALSE,
                                                    options.List(), GdalProgress::call, &reported));
    reported.rethrow_if_stopped();
    if (!ds) throw Error("write", "cannot write '" + path + "'" + errors.suffix());
    return ds;
}

void write_label_raster(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                        const segment::RegionGraph& graph, const std::string& path, bool overwrite,
                        const ProgressFn& progress) {
    check_grid_size(dem, pixels.size());
    ensure_gdal_registered();
    const GdalErrorCapture errors;
    check_output_path(path + ".aux.xml", overwrite);
    check_output_path(label_style_path(path), overwrite);
    // UInt16 with a colour table while the ids fit (the CLI's contract; GeoTIFF holds colour
    // tables for 8 and 16-bit bands only), UInt32 beyond.
    const bool paletted = graph.regions.size() < 65536;
    const GDALDataType type = paletted ? GDT_UInt16 : GDT_UInt32;
    AtomicOutput output(path, overwrite);
    TemporaryFiles temporary(output);
    std::vector<std::string> files;
    {
        // The labels as GDAL sees them without a copy: a MEM band over `pixels`, read through
        // a VRT as `type`, with the colour table, NoData and description.
        auto mem = labels_in_place(dem, {&pixels}, path, errors);
        std::unique_ptr<VRTDataset> source(
            static_cast<VRTDataset*>(GDALDataset::FromHandle(VRTCreate(dem.width, dem.height))));
        // A DEM read without geotransform gets the grid terrain used (docs/outputs.md).
        set_grid_georeference(*source, dem, true);
        source->AddBand(type, nullptr);
        auto* band = static_cast<VRTSourcedRasterBand*>(source->GetRasterBand(1));
        band->AddSimpleSource(mem->GetRasterBand(1));
        band->SetNoDataValue(0);
        band->SetDescription("region id");
        if (paletted) {
            const auto table = region_colour_table(graph.regions.size());
            band->SetColorInterpretation(GCI_PaletteIndex);
            if (band->SetColorTable(const_cast<GDALColorTable*>(&table)) != CE_None)
                throw Error("write",
                            "cannot store the colour table of '" + path + "'" + errors.suffix());
        }
        auto ds = write_cloud_optimized(dem, *source, output.temp_path(), path, errors, progress);
        source.reset();
        mem.reset();
        // The attribute table goes to the .aux.xml (GeoTIFF has none), written on closing.
        auto rat = region_attribute_table(graph);
        if (ds->GetRasterBand(1)->SetDefaultRAT(&rat) != CE_None)
            throw Error("write",
                        "cannot store the attribute table of '" + path + "'" + errors.suffix());
        files = dataset_files(ds.get());
        close_dataset(ds, path, errors);  // also writes the .aux.xml
    }
    files.push_back(output.temp_path() + ".aux.xml");
    commit_dataset(output, files, overwrite);
    temporary.release();
    write_file_atomically(label_style_path(path), overwrite,
                          [&](std::ostream& out) { write_label_style(out, graph); });
}

}  // namespace terrain::io
