#pragma once
// Private: what the OGR layers of the io layer share (regions.gpkg's layers, the craters'):
// attribute fields, fixed dates, so that the same input gives the same bytes, and the WKT2
// definitions of their CRSs, which QGIS needs for the IAU's planetary CRSs. Not installed.

#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <string>
#include <vector>

#include "gdal_support.hpp"
#include "region_attributes.hpp"

namespace terrain::io {

// While alive, GeoPackage stamps this thread's writes (creation, SQL that changes a table,
// closing) with a fixed time instead of the current one.
class FixedGpkgDate {
  public:
    FixedGpkgDate();
    ~FixedGpkgDate();
    FixedGpkgDate(const FixedGpkgDate&) = delete;
    FixedGpkgDate& operator=(const FixedGpkgDate&) = delete;
};

// One OGR field per attribute (Integer64, Real or String, as the value), in order; throws
// naming `path` on failure.
void create_attribute_fields(OGRLayer& layer, const std::vector<Attribute>& attributes,
                             const std::string& path, const GdalErrorCapture& errors);
// The attributes' values into the feature's fields, in the same order.
void set_attribute_fields(OGRFeature& feature, const std::vector<Attribute>& attributes);

// Runs one SQL statement on a GeoPackage (SQLite's own dialect); throws on failure.
void execute_sql(GDALDataset& ds, const std::string& sql, const std::string& path,
                 const GdalErrorCapture& errors);

// `text` as an SQL string literal.
std::string sql_quoted(const std::string& text);

// Every SRS of a GeoPackage not yet given one also as WKT2 (the gpkg_crs_wkt extension's
// definition_12_063 column), which readers prefer to the WKT1 `definition`. WKT1 cannot say
// which version of an authority a code belongs to (IAU_2015 is written AUTHORITY["IAU", ...]),
// and QGIS 3.22 finds no CRS at all for such a code; WKT2's ID["IAU",30115,2015] it names.
// `srs` is the CRS of the layers added since the last call; other rows (GDAL's EPSG:4326) are
// converted from their WKT1.
void add_wkt2_definitions(GDALDataset& ds, const OGRSpatialReference* srs, const std::string& path,
                          const GdalErrorCapture& errors);

}  // namespace terrain::io
