#include "gdal_support.hpp"

#include <gdal.h>

#include <mutex>
#include <string>

#include "terrain/core/error.hpp"

namespace terrain::io {

void ensure_gdal_registered() {
    static std::once_flag once;
    std::call_once(once, [] { GDALAllRegister(); });
}

void check_grid_size(const Dem& grid, std::size_t count) {
    if (count != grid.size())
        throw Error("write", "raster of " + std::to_string(count) + " pixels for a " +
                                 std::to_string(grid.width) + "x" + std::to_string(grid.height) +
                                 " grid");
}

std::unique_ptr<GDALDataset> create_grid_tiff(const Dem& grid, bool with_transform,
                                              const std::string& temp_path, const std::string& path,
                                              GDALDataType type, const char* const* options,
                                              const GdalErrorCapture& errors) {
    GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
    std::unique_ptr<GDALDataset> ds(driver->Create(temp_path.c_str(), grid.width, grid.height, 1,
                                                   type, const_cast<char**>(options)));
    if (!ds) throw Error("write", "cannot create '" + path + "'" + errors.suffix());
    set_grid_georeference(*ds, grid, with_transform);
    return ds;
}

void set_grid_georeference(GDALDataset& ds, const Dem& grid, bool with_transform) {
    if (with_transform) {
        GeoTransform t = grid.transform;
        ds.SetGeoTransform(t.data());
    }
    if (!grid.crs_wkt.empty()) {
        // A planetary CRS as the IAU_2015 CRS of its body, when PROJ holds it.
        OGRSpatialReference srs;
        if (srs.SetFromUserInput(geo::output_crs_wkt(grid.crs_wkt).c_str()) == OGRERR_NONE)
            ds.SetSpatialRef(&srs);
    }
}

bool add_band_in_place(GDALDataset& mem, GDALDataType type, const void* data,
                       std::size_t pixel_offset, std::size_t line_offset) {
    char pointer[64] = {};
    CPLPrintPointer(pointer, const_cast<void*>(data), sizeof pointer);
    CPLStringList options;
    options.SetNameValue("DATAPOINTER", pointer);
    options.SetNameValue("PIXELOFFSET", std::to_string(pixel_offset).c_str());
    options.SetNameValue("LINEOFFSET", std::to_string(line_offset).c_str());
    return mem.AddBand(type, options.List()) == CE_None;
}

void close_dataset(std::unique_ptr<GDALDataset>& ds, const std::string& path,
                   const GdalErrorCapture& errors) {
    CPLErrorReset();
    ds.reset();  // closes the file, writing what is cached
    if (CPLGetLastErrorType() >= CE_Failure)
        throw Error("write", "closing '" + path + "' failed" + errors.suffix());
}

}  // namespace terrain::io
