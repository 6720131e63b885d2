#pragma once
// Private: a GeoJSON FeatureCollection written one feature per line with terrain's
// JsonWriter (not installed). GDAL's GeoJSON driver records only EPSG CRSs, so a planetary
// lon/lat CRS would be lost; here it goes into the 2008 "crs" member, which GDAL reads back.

#include <cstdint>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "region_attributes.hpp"
#include "terrain/core/json_writer.hpp"

namespace terrain::io {

// The CRS of a DEM without one: a local engineering CRS (WKT2 ENGCRS, easting and northing
// in metres, no datum on any body), so that GDAL and its clients read the coordinates as a
// local grid rather than longitude/latitude. Also the polygons' SRS in GPKG and other formats.
const std::string& local_grid_crs_wkt();

class GeoJsonFile {
  public:
    // `crs_name`: empty for none (RFC 7946 lon/lat, or coordinates without CRS). Coordinates
    // are rounded to `decimals` decimals.
    GeoJsonFile(std::ostream& out, std::string_view name, const std::string& crs_name,
                int decimals);

    // One feature: {"type": "Feature", "id": id, "properties": {...}, "geometry": ...}, the
    // geometry written by write_geometry(JsonWriter&) (or null when it writes nothing useful:
    // pass a function calling json.null()).
    template <class GeometryFn>
    void feature(std::int64_t id, const std::vector<Attribute>& properties,
                 GeometryFn&& write_geometry) {
        out_ << (first_ ? "\n" : ",\n");
        first_ = false;
        JsonWriter json(out_, false);
        json.begin_object().field("type", "Feature").field("id", id);
        json.key("properties").begin_object();
        write_attributes(json, properties);
        json.end_object().key("geometry");
        write_geometry(json);
        json.end_object();
    }

    // [x, y] or [x, y, z], rounded.
    void position(JsonWriter& json, double x, double y) const;
    void position(JsonWriter& json, double x, double y, double z) const;

    void finish();  // closes the collection

  private:
    double round(double v) const;
    std::ostream& out_;
    double scale_;
    bool first_ = true;
};

}  // namespace terrain::io
