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
    if (pixels.size() != grid.size())
        throw Error("write", "raster of " + std::to_string(pixels.size()) + " pixels for a " +
                                 std::to_string(grid.width) + "x" + std::to_string(grid.height) +
                                 " grid");
    ensure_gdal_registered();
    const GdalErrorCapture errors;
    AtomicOutput output(path, overwrite);
    {
        GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
        const char* options[] = {"COMPRESS=DEFLATE", "PREDICTOR=3", "TILED=YES", nullptr};
        std::unique_ptr<GDALDataset> ds(driver->Create(output.temp_path().c_str(), grid.width,
                                                       grid.height, 1, GDT_Float32,
                                                       const_cast<char**>(options)));
        if (!ds) throw Error("write", "cannot create '" + path + "'" + errors.suffix());
        if (grid.has_transform) {
            GeoTransform t = grid.transform;
            ds->SetGeoTransform(t.data());
        }
        if (!grid.crs_wkt.empty()) {
            OGRSpatialReference srs;
            if (srs.SetFromUserInput(grid.crs_wkt.c_str()) == OGRERR_NONE) ds->SetSpatialRef(&srs);
        }
        GDALRasterBand* band = ds->GetRasterBand(1);
        band->SetNoDataValue(std::nan(""));
        band->SetDescription(description.c_str());
        std::vector<float> copy = pixels;  // RasterIO takes a non-const buffer
        if (band->RasterIO(GF_Write, 0, 0, grid.width, grid.height, copy.data(), grid.width,
                           grid.height, GDT_Float32, 0, 0) != CE_None)
            throw Error("write", "writing '" + path + "' failed" + errors.suffix());
        CPLErrorReset();
        ds.reset();  // closes the file, writing what is cached
        if (CPLGetLastErrorType() >= CE_Failure)
            throw Error("write", "closing '" + path + "' failed" + errors.suffix());
    }
    output.commit();
}

}  // namespace terrain::io
