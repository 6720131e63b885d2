#pragma once
// Private helpers for the GDAL-facing code of the io layer (not installed).

#include <cpl_error.h>
#include <ogr_spatialref.h>

#include <gdal_priv.h>
#include <gdal_rat.h>

#include <cstddef>
#include <exception>
#include <memory>
#include <string>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/internal/geo/iau_crs.hpp"
#include "terrain/internal/geo/ogr_support.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {

// The regions' raster attribute table (labels.tif, each band of a sweep's): thematic, one row
// per region in id order, every property but "fill", and the colour as Red/Green/Blue/Alpha.
GDALDefaultRasterAttributeTable region_attribute_table(const segment::RegionGraph& graph);

// GDALAllRegister once per process.
void ensure_gdal_registered();

using geo::GdalErrorCapture;

// Throws terrain::Error (stage "write") unless `count` is one value per pixel of `grid`.
void check_grid_size(const Dem& grid, std::size_t count);

// The grid's geotransform (when `with_transform`) and CRS (the body's IAU_2015 CRS when PROJ
// holds it) on a dataset.
void set_grid_georeference(GDALDataset& ds, const Dem& grid, bool with_transform);

// A GeoTIFF of the grid's size with `type` bands, its geotransform (when `with_transform`)
// and CRS; throws terrain::Error naming `path` when GDAL cannot create it.
std::unique_ptr<GDALDataset> create_grid_tiff(const Dem& grid, bool with_transform,
                                              const std::string& temp_path, const std::string& path,
                                              GDALDataType type, const char* const* options,
                                              const GdalErrorCapture& errors);

// Adds to a MEM dataset a band of `type` over memory the caller keeps (no copy): its first
// value at `data`, values `pixel_offset` bytes apart along a row, rows `line_offset` bytes
// apart. Returns whether GDAL took it.
bool add_band_in_place(GDALDataset& mem, GDALDataType type, const void* data,
                       std::size_t pixel_offset, std::size_t line_offset);

// Closes the dataset (writing what GDAL cached) and throws if that failed.
void close_dataset(std::unique_ptr<GDALDataset>& ds, const std::string& path,
                   const GdalErrorCapture& errors);

// GDAL's progress (a GDALProgressFunc and its argument) to a terrain callback, as "write":
// an exception (a cancel) must not cross GDAL's C code, so it is kept, GDAL is told to stop,
// and the caller rethrows it (rethrow_if_stopped) once GDAL has returned.
struct GdalProgress {
    const ProgressFn& fn;
    std::exception_ptr stopped{};
    static int CPL_STDCALL call(double fraction, const char*, void* self) {
        auto& p = *static_cast<GdalProgress*>(self);
        try {
            report_progress(p.fn, fraction, "write");
            return TRUE;
        } catch (...) {
            p.stopped = std::current_exception();
            return FALSE;
        }
    }
    void rethrow_if_stopped() const {
        if (stopped) std::rethrow_exception(stopped);
    }
};

}  // namespace terrain::io
