#pragma once
// Private helpers for the code that calls OGR/PROJ (geo and io; not installed).

#include <cpl_error.h>
#include <ogr_spatialref.h>

#include <memory>
#include <string>

namespace terrain::geo {

// A CRS (any text SetFromUserInput takes) and the transformation from it to longitude and
// latitude in degrees on the same body (its geographic base), lon first. `to_lonlat` is null
// when the CRS cannot be read or transformed. Not thread-safe: one per thread.
struct LonLatTransform {
    std::unique_ptr<OGRSpatialReference> source, geographic;
    std::unique_ptr<OGRCoordinateTransformation> to_lonlat;
};
LonLatTransform make_lonlat_transform(const std::string& crs);

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

}  // namespace terrain::geo
