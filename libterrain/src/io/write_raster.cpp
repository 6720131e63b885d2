#include "terrain/io/write_raster.hpp"

#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <cmath>
#include <memory>

#include "gdal_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/output_file.hpp"

namespace terrain::io {

void write_float_raster(const Dem& grid, const std::vector<float>& pixels, const std::string& path,
                        bool overwrite, const std::string& description) {
    check_grid_size(grid, pixels.size());
    ensure_gdal_registered();
    const GdalErrorCapture errors;
    AtomicOutput output(path, overwrite);
    {
        const char* options[] = {"COMPRESS=DEFLATE", "PREDICTOR=3", "TILED=YES", nullptr};
        auto ds = create_grid_tiff(grid, grid.has_transform, output.temp_path(), path, GDT_Float32,
                                   options, errors);
        GDALRasterBand* band = ds->GetRasterBand(1);
        band->SetNoDataValue(std::nan(""));
        band->SetDescription(description.c_str());
        std::vector<float> copy = pixels;  // RasterIO takes a non-const buffer
        if (band->RasterIO(GF_Write, 0, 0, grid.width, grid.height, copy.data(), grid.width,
                           grid.height, GDT_Float32, 0, 0) != CE_None)
            throw Error("write", "writing '" + path + "' failed" + errors.suffix());
        close_dataset(ds, path, errors);
    }
    output.commit();
}

}  // namespace terrain::io
