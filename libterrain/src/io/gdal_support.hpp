#pragma once
// Private helpers for the GDAL-facing code of libterrain (not installed).

#include <cpl_error.h>
#include <ogr_spatialref.h>

#include <gdal_priv.h>

#include <cstddef>
#include <memory>
#include <string>

#include "terrain/core/dem.hpp"

namespace terrain::io {

// A CRS (any text SetFromUserInput takes) and the transformation from it to longitude and
// latitude in degrees on the same body (its geographic base), lon first. `to_lonlat` is null
// when the CRS cannot be read or transformed. Not thread-safe: one per thread.
struct LonLatTransform {
    std::unique_ptr<OGRSpatialReference> source, geographic;
    std::unique_ptr<OGRCoordinateTransformation> to_lonlat;
};
LonLatTransform make_lonlat_transform(const std::string& crs);

// GDALAllRegister once per process.
void ensure_gdal_registered();

// While alive, GDAL errors and warnings raised on this thread are kept here instead of being
// printed (the library never prints). suffix() gives ": <last error>" for a message.
class GdalErrorCapture {
  public:
    GdalErrorCapture();
    ~GdalErrorCapture();
    GdalErrorCapture(const GdalErrorCapture&) = delete;
    GdalErrorCapture& operator=(const GdalErrorCapture&) = delete;

    const std::string& last_error() const { return last_error_; }
    std::string suffix() const { return last_error_.empty() ? "" : " (" + last_error_ + ")"; }

  private:
    static void CPL_STDCALL handler(CPLErr level, CPLErrorNum number, const char* message);
    std::string last_error_;
};

// Throws terrain::Error (stage "write") unless `count` is one value per pixel of `grid`.
void check_grid_size(const Dem& grid, std::size_t count);

// A GeoTIFF of the grid's size with `type` bands, its geotransform (when `with_transform`)
// and CRS; throws terrain::Error naming `path` when GDAL cannot create it.
std::unique_ptr<GDALDataset> create_grid_tiff(const Dem& grid, bool with_transform,
                                              const std::string& temp_path, const std::string& path,
                                              GDALDataType type, const char* const* options,
                                              const GdalErrorCapture& errors);

// Closes the dataset (writing what GDAL cached) and throws if that failed.
void close_dataset(std::unique_ptr<GDALDataset>& ds, const std::string& path,
                   const GdalErrorCapture& errors);

}  // namespace terrain::io
