#include "geojson_file.hpp"

#include <cmath>

namespace terrain::io {

const std::string& local_grid_crs_wkt() {
    static const std::string wkt =
        "ENGCRS[\"terrain local grid\",EDATUM[\"unknown\"],CS[Cartesian,2],"
        "AXIS[\"easting (X)\",east,ORDER[1],LENGTHUNIT[\"metre\",1]],"
        "AXIS[\"northing (Y)\",north,ORDER[2],LENGTHUNIT[\"metre\",1]]]";
    return wkt;
}

GeoJsonFile::GeoJsonFile(std::ostream& out, std::string_view name, const std::string& crs_name,
                         int decimals)
    : out_(out), scale_(std::pow(10.0, decimals)) {
    out_ << "{\n\"type\": \"FeatureCollection\",\n\"name\": " << JsonWriter::escape(name) << ",\n";
    if (!crs_name.empty())
        out_ << "\"crs\": {\"type\": \"name\", \"properties\": {\"name\": "
             << JsonWriter::escape(crs_name) << "}},\n";
    out_ << "\"features\": [";
}

double GeoJsonFile::round(double v) const {
    return std::round(v * scale_) / scale_;
}

void GeoJsonFile::position(JsonWriter& json, double x, double y) const {
    json.begin_array().value(round(x)).value(round(y)).end_array();
}

void GeoJsonFile::position(JsonWriter& json, double x, double y, double z) const {
    json.begin_array().value(round(x)).value(round(y)).value(round(z)).end_array();
}

void GeoJsonFile::finish() {
    out_ << "\n]\n}\n";
}

}  // namespace terrain::io
