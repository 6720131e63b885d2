#include <gdal_priv.h>
#include <gdal_rat.h>
#include <ogr_spatialref.h>

#include <memory>
#include <variant>

#include "dataset_files.hpp"
#include "gdal_support.hpp"
#include "region_attributes.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/region_colour.hpp"
#include "terrain/io/write_label_raster.hpp"

namespace terrain::io {
namespace {

// One row per region: its attributes (but "fill") and its colour. Thematic, with the id as
// the value column, so GDAL and QGIS map pixel values to rows.
GDALDefaultRasterAttributeTable attribute_table(const segment::RegionGraph& graph) {
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

}  // namespace

void write_label_raster(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                        const segment::RegionGraph& graph, const std::string& path,
                        bool overwrite) {
    check_grid_size(dem, pixels.size());
    ensure_gdal_registered();
    const GdalErrorCapture errors;
    check_output_path(path + ".aux.xml", overwrite);
    AtomicOutput output(path, overwrite);
    TemporaryFiles temporary(output);
    std::vector<std::string> files;
    {
        const char* options[] = {"COMPRESS=DEFLATE", "PREDICTOR=2", "TILED=YES", nullptr};
        // A DEM read without geotransform gets the grid terrain used (docs/outputs.md).
        auto ds =
            create_grid_tiff(dem, true, output.temp_path(), path, GDT_UInt32, options, errors);
        GDALRasterBand* band = ds->GetRasterBand(1);
        band->SetNoDataValue(0);
        band->SetDescription("region id");
        auto rat = attribute_table(graph);
        if (band->SetDefaultRAT(&rat) != CE_None)
            throw Error("write",
                        "cannot store the attribute table of '" + path + "'" + errors.suffix());
        if (band->RasterIO(GF_Write, 0, 0, dem.width, dem.height,
                           const_cast<std::uint32_t*>(pixels.data()), dem.width, dem.height,
                           GDT_UInt32, 0, 0) != CE_None)
            throw Error("write", "writing '" + path + "' failed" + errors.suffix());
        ds->FlushCache();
        files = dataset_files(ds.get());
        close_dataset(ds, path, errors);  // also writes the .aux.xml
    }
    files.push_back(output.temp_path() + ".aux.xml");
    commit_dataset(output, files, overwrite);
    temporary.release();
}

}  // namespace terrain::io
