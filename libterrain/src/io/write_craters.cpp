#include "terrain/io/write_craters.hpp"

#include <cmath>

#include "../geo/iau_crs.hpp"
#include "dataset_files.hpp"
#include "geojson_file.hpp"
#include "lonlat_frame.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/json_writer.hpp"

namespace terrain::io {
namespace {

// A number as JSON writes it (shortest round trip); NaN as an empty field.
std::string field(double x) {
    return std::isfinite(x) ? JsonWriter::number(x) : std::string();
}

}  // namespace

void write_craters_csv(const segment::CraterTable& table, const std::string& path, bool overwrite) {
    write_file_atomically(path, overwrite, [&](std::ostream& out) {
        out << (table.lonlat ? "id,lon,lat" : "id,x,y")
            << ",col,row,diameter_m,depth_m,rim_height_m,circularity,rim_fraction,fit_rms_m,"
               "field_scale_m,floor_region,rim_regions,confidence\n";
        for (const auto& k : table.craters) {
            std::string rims;
            for (const auto r : k.rim_regions)
                rims += (rims.empty() ? "" : " ") + std::to_string(r);
            out << k.id << ',' << field(k.lon) << ',' << field(k.lat) << ',' << field(k.col) << ','
                << field(k.row) << ',' << field(k.diameter_m) << ',' << field(k.depth_m) << ','
                << field(k.rim_height_m) << ',' << field(k.circularity) << ','
                << field(k.rim_fraction) << ',' << field(k.fit_rms_m) << ','
                << field(k.field_scale_m) << ',' << k.floor_region << ',' << rims << ','
                << field(k.confidence) << '\n';
        }
    });
}

void write_craters_geojson(const segment::CraterTable& table, const std::string& path,
                           bool overwrite) {
    write_file_atomically(path, overwrite, [&](std::ostream& out) {
        const std::string crs = table.lonlat
                                    ? geojson_crs_name(geo::output_crs_wkt(table.lonlat_crs_wkt))
                                    : local_grid_crs_wkt();
        GeoJsonFile file(out, "craters", crs, table.lonlat ? 9 : 6);
        std::int64_t id = 0;
        for (const auto& k : table.craters) {
            std::string rims;
            for (const auto r : k.rim_regions)
                rims += (rims.empty() ? "" : " ") + std::to_string(r);
            std::vector<Attribute> a{{"kind", std::string("centre")},
                                     {"id", std::int64_t{k.id}},
                                     {table.lonlat ? "lon" : "x", k.lon},
                                     {table.lonlat ? "lat" : "y", k.lat},
                                     {"diameter_m", k.diameter_m},
                                     {"depth_m", k.depth_m},
                                     {"rim_height_m", k.rim_height_m},
                                     {"circularity", k.circularity},
                                     {"rim_fraction", k.rim_fraction},
                                     {"fit_rms_m", k.fit_rms_m},
                                     {"field_scale_m", k.field_scale_m},
                                     {"floor_region", std::int64_t{k.floor_region}},
                                     {"rim_regions", rims},
                                     {"confidence", k.confidence}};
            file.feature(++id, a, [&](JsonWriter& json) {
                json.begin_object().field("type", "Point").key("coordinates");
                file.position(json, k.lon, k.lat);
                json.end_object();
            });
            a.front().value = std::string("rim");
            file.feature(++id, a, [&](JsonWriter& json) {
                json.begin_object().field("type", "Polygon").key("coordinates").begin_array();
                json.begin_array();
                for (const auto& p : k.rim) file.position(json, p[0], p[1]);
                json.end_array().end_array().end_object();
            });
        }
        file.finish();
    });
}

void write_craters_scc(const segment::CraterTable& table, const Body& body, double area_m2,
                       const std::string& path, bool overwrite) {
    if (!table.lonlat)
        throw Error("write", "craters.scc needs longitudes and latitudes: the DEM has no CRS");
    write_file_atomically(path, overwrite, [&](std::ostream& out) {
        const double a = body.semi_major_axis / 1000, c = body.semi_minor_axis() / 1000;
        out << "# Spatial crater count\n#\n# Craters found by terrain segment (craters.csv)\n#\n"
            << "# Ellipsoid axes:\n"
            << "a_axis_radius = " << JsonWriter::number(a) << " <km>\n"
            << "b_axis_radius = " << JsonWriter::number(a) << " <km>\n"
            << "c_axis_radius = " << JsonWriter::number(c) << " <km>\n"
            << "coordinate_system_name = " << (body.name.empty() ? "unknown" : body.name)
            << "\n#\n# The counted area: the DEM's valid pixels on the body\n"
            << "Total_area = " << JsonWriter::number(area_m2 / 1e6) << " <km^2>\n"
            << "#\n# crater_diameters:\ncrater = {diam,lon,lat\n";
        for (const auto& k : table.craters)
            out << JsonWriter::number(k.diameter_m / 1000) << '\t' << JsonWriter::number(k.lon)
                << '\t' << JsonWriter::number(k.lat) << '\n';
        out << "}\n";
    });
}

}  // namespace terrain::io
