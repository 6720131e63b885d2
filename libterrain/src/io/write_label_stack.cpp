#include <gdal_pam.h>
#include <gdal_priv.h>

#include <memory>
#include <string>
#include <vector>

#include "dataset_files.hpp"
#include "gdal_support.hpp"
#include "label_style.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/write_label_raster.hpp"
#include "terrain/io/write_label_stack.hpp"

namespace terrain::io {

void write_label_stack(const Dem& dem, const std::vector<std::vector<std::uint32_t>>& bands,
                       const std::vector<std::string>& descriptions, const std::string& path,
                       bool overwrite) {
    write_label_stack(dem, bands, descriptions, {}, path, overwrite);
}

void write_label_stack(const Dem& dem, const std::vector<std::vector<std::uint32_t>>& bands,
                       const std::vector<std::string>& descriptions,
                       const std::vector<const segment::RegionGraph*>& graphs,
                       const std::string& path, bool overwrite) {
    const auto n = static_cast<std::size_t>(dem.width) * static_cast<std::size_t>(dem.height);
    if (bands.empty() || bands.size() != descriptions.size())
        throw Error("write", "label stack: one description per band is needed");
    for (const auto& b : bands)
        if (b.size() != n) throw Error("write", "label stack: a band does not match the DEM grid");
    if (!graphs.empty() && graphs.size() != bands.size())
        throw Error("write", "label stack: one region graph per band is needed");
    ensure_gdal_registered();
    const GdalErrorCapture errors;
    if (!graphs.empty()) {
        check_output_path(path + ".aux.xml", overwrite);
        check_output_path(label_style_path(path), overwrite);
    }
    AtomicOutput output(path, overwrite);
    TemporaryFiles temporary(output);
    // One UInt32 band per scale, read in place, written as a Cloud-Optimized GeoTIFF (pixel
    // interleaved, as GDAL's COG driver writes several bands).
    std::vector<const std::vector<std::uint32_t>*> values;
    for (const auto& b : bands) values.push_back(&b);
    auto mem = labels_in_place(dem, values, path, errors);
    for (std::size_t i = 0; i < bands.size(); ++i) {
        GDALRasterBand* band = mem->GetRasterBand(static_cast<int>(i + 1));
        band->SetNoDataValue(0);
        band->SetDescription(descriptions[i].c_str());
    }
    auto ds = write_cloud_optimized(dem, *mem, output.temp_path(), path, errors);
    mem.reset();
    for (std::size_t i = 0; i < bands.size() && !graphs.empty(); ++i) {
        // The attribute tables go to the .aux.xml (the file is open read-only: GDAL keeps what
        // is set on it there), and band 1's colour table too when its ids fit in 16 bits:
        // GeoTIFF stores one only for 8 and 16-bit single-sample images, and GDAL reads one
        // from the .aux.xml for band 1. The GeoTIFF itself is the same with or without them.
        GDALRasterBand* band = ds->GetRasterBand(static_cast<int>(i + 1));
        auto rat = region_attribute_table(*graphs[i]);
        if (band->SetDefaultRAT(&rat) != CE_None)
            throw Error("write", "cannot store the attribute table of band " +
                                     std::to_string(i + 1) + " of '" + path + "'" +
                                     errors.suffix());
        auto* pam = dynamic_cast<GDALPamRasterBand*>(band);
        if (pam && i == 0 && graphs[i]->regions.size() < 65536) {
            const auto table = region_colour_table(graphs[i]->regions.size());
            if (pam->GDALPamRasterBand::SetColorInterpretation(GCI_PaletteIndex) != CE_None ||
                pam->GDALPamRasterBand::SetColorTable(const_cast<GDALColorTable*>(&table)) !=
                    CE_None)
                throw Error("write", "cannot store the colour table of band " +
                                         std::to_string(i + 1) + " of '" + path + "'" +
                                         errors.suffix());
        }
    }
    auto files = dataset_files(ds.get());
    CPLErrorReset();
    ds.reset();
    if (CPLGetLastErrorType() >= CE_Failure)
        throw Error("write", "closing '" + path + "' failed" + errors.suffix());
    if (!graphs.empty()) files.push_back(output.temp_path() + ".aux.xml");
    commit_dataset(output, files, overwrite);
    temporary.release();
    // QGIS's style: band 1 (the first scale) in its regions' colours.
    if (!graphs.empty())
        write_file_atomically(label_style_path(path), overwrite, [&](std::ostream& out) {
            write_label_style(out, *graphs.front(), 1);
        });
}

}  // namespace terrain::io
