#include "terrain/io/write_craters.hpp"

#include <ogrsf_frmts.h>

#include <cmath>
#include <memory>
#include <variant>

#include "dataset_files.hpp"
#include "geojson_file.hpp"
#include "gpkg_support.hpp"
#include "lonlat_frame.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/internal/geo/iau_crs.hpp"

namespace terrain::io {
namespace {

// The rim regions' ids, space-separated.
std::string rim_list(const segment::Crater& k) {
    std::string rims;
    for (const auto r : k.rim_regions) rims += (rims.empty() ? "" : " ") + std::to_string(r);
    return rims;
}

// The columns of a crater as feature attributes (`kind` first).
std::vector<Attribute> crater_attributes(const segment::CraterTable& table,
                                         const segment::Crater& k, const std::string& kind) {
    return {{"kind", kind},
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
            {"rim_regions", rim_list(k)},
            {"confidence", k.confidence}};
}

// The CRS of the craters' coordinates, as the regions' polygons name it.
std::string crater_crs_wkt(const segment::CraterTable& table) {
    return table.lonlat ? geo::output_crs_wkt(table.lonlat_crs_wkt) : local_grid_crs_wkt();
}

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
            out << k.id << ',' << field(k.lon) << ',' << field(k.lat) << ',' << field(k.col) << ','
                << field(k.row) << ',' << field(k.diameter_m) << ',' << field(k.depth_m) << ','
                << field(k.rim_height_m) << ',' << field(k.circularity) << ','
                << field(k.rim_fraction) << ',' << field(k.fit_rms_m) << ','
                << field(k.field_scale_m) << ',' << k.floor_region << ',' << rim_list(k) << ','
                << field(k.confidence) << '\n';
        }
    });
}

void write_craters_geojson(const segment::CraterTable& table, const std::string& path,
                           bool overwrite) {
    write_file_atomically(path, overwrite, [&](std::ostream& out) {
        const std::string crs =
            table.lonlat ? geojson_crs_name(crater_crs_wkt(table)) : local_grid_crs_wkt();
        GeoJsonFile file(out, "craters", crs, table.lonlat ? 9 : 6);
        std::int64_t id = 0;
        for (const auto& k : table.craters) {
            auto a = crater_attributes(table, k, "centre");
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

void add_crater_layers(const segment::CraterTable& table, const std::string& path) {
    ensure_gdal_registered();
    const GdalErrorCapture errors;
    const FixedGpkgDate fixed_date;
    std::unique_ptr<GDALDataset> ds(
        GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE));
    if (!ds)
        throw Error("write", "cannot open '" + path + "' to add the craters" + errors.suffix());
    OGRSpatialReference srs;
    srs.SetFromUserInput(crater_crs_wkt(table).c_str());
    srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    const auto fail = [&](const std::string& what) {
        return Error("write", "cannot " + what + " in '" + path + "'" + errors.suffix());
    };
    const segment::Crater none;
    for (const bool rims : {false, true}) {
        OGRLayer* layer = ds->CreateLayer(rims ? "crater_rims" : "craters", &srs,
                                          rims ? wkbPolygon : wkbPoint, nullptr);
        if (!layer) throw fail("create the crater layers");
        create_attribute_fields(*layer, crater_attributes(table, none, ""), path, errors);
        const bool transaction = ds->StartTransaction() == OGRERR_NONE;
        for (const auto& k : table.craters) {
            OGRFeature feature(layer->GetLayerDefn());
            set_attribute_fields(feature, crater_attributes(table, k, rims ? "rim" : "centre"));
            if (rims) {
                auto ring = std::make_unique<OGRLinearRing>();
                for (const auto& p : k.rim) ring->addPoint(p[0], p[1]);
                auto polygon = std::make_unique<OGRPolygon>();
                polygon->addRingDirectly(ring.release());
                feature.SetGeometryDirectly(polygon.release());
            } else {
                feature.SetGeometryDirectly(new OGRPoint(k.lon, k.lat));
            }
            if (layer->CreateFeature(&feature) != OGRERR_NONE)
                throw fail("write crater " + std::to_string(k.id));
        }
        if (transaction && ds->CommitTransaction() != OGRERR_NONE) throw fail("write the craters");
    }
    add_wkt2_definitions(*ds, &srs, path, errors);
    CPLErrorReset();
    ds.reset();
    if (CPLGetLastErrorType() >= CE_Failure)
        throw Error("write", "closing '" + path + "' failed" + errors.suffix());
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
