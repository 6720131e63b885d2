#include "gpkg_support.hpp"

#include <cpl_conv.h>
#include <ogrsf_frmts.h>

#include <cstdint>
#include <variant>
#include <vector>

#include "terrain/core/error.hpp"

namespace terrain::io {

FixedGpkgDate::FixedGpkgDate() {
    CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", "2000-01-01T00:00:00.000Z");
}
FixedGpkgDate::~FixedGpkgDate() {
    CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", nullptr);
}

void create_attribute_fields(OGRLayer& layer, const std::vector<Attribute>& attributes,
                             const std::string& path, const GdalErrorCapture& errors) {
    for (const auto& [name, value] : attributes) {
        const OGRFieldType type =
            std::holds_alternative<std::int64_t>(value)
                ? OFTInteger64
                : (std::holds_alternative<double>(value) ? OFTReal : OFTString);
        OGRFieldDefn field(name.c_str(), type);
        if (layer.CreateField(&field) != OGRERR_NONE)
            throw Error("write",
                        "cannot create field '" + name + "' in '" + path + "'" + errors.suffix());
    }
}

void set_attribute_fields(OGRFeature& feature, const std::vector<Attribute>& attributes) {
    int k = 0;
    for (const auto& [name, value] : attributes) {
        if (const auto* n = std::get_if<std::int64_t>(&value))
            feature.SetField(k, static_cast<GIntBig>(*n));
        else if (const auto* d = std::get_if<double>(&value))
            feature.SetField(k, *d);
        else
            feature.SetField(k, std::get<std::string>(value).c_str());
        ++k;
    }
}

void execute_sql(GDALDataset& ds, const std::string& sql, const std::string& path,
                 const GdalErrorCapture& errors) {
    CPLErrorReset();
    if (OGRLayer* result = ds.ExecuteSQL(sql.c_str(), nullptr, nullptr))
        ds.ReleaseResultSet(result);
    if (CPLGetLastErrorType() >= CE_Failure)
        throw Error("write", "cannot record the CRS of '" + path + "'" + errors.suffix());
}

std::string sql_quoted(const std::string& text) {
    std::string out = "'";
    for (const char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
    return out + "'";
}

void add_wkt2_definitions(GDALDataset& ds, const OGRSpatialReference* srs, const std::string& path,
                          const GdalErrorCapture& errors) {
    bool has_column = false;
    if (OGRLayer* info =
            ds.ExecuteSQL("PRAGMA table_info(gpkg_spatial_ref_sys)", nullptr, nullptr)) {
        for (auto& row : *info)
            if (std::string(row->GetFieldAsString("name")) == "definition_12_063")
                has_column = true;
        ds.ReleaseResultSet(info);
    }
    if (!has_column) {
        execute_sql(ds,
                    "ALTER TABLE gpkg_spatial_ref_sys ADD COLUMN definition_12_063 TEXT NOT NULL "
                    "DEFAULT 'undefined'",
                    path, errors);
        execute_sql(ds,
                    "INSERT INTO gpkg_extensions (table_name, column_name, extension_name, "
                    "definition, scope) VALUES ('gpkg_spatial_ref_sys', 'definition_12_063', "
                    "'gpkg_crs_wkt', 'http://www.geopackage.org/spec120/#extension_crs_wkt', "
                    "'read-write')",
                    path, errors);
    }
    struct Row {
        std::int64_t id;
        std::string wkt1;
        bool layers;  // the SRS of the layers, made by GDAL from `srs`
    };
    std::vector<Row> rows;
    if (OGRLayer* table = ds.ExecuteSQL(
            "SELECT srs_id, definition, srs_id IN (SELECT srs_id FROM gpkg_geometry_columns) "
            "FROM gpkg_spatial_ref_sys WHERE definition <> 'undefined' AND definition_12_063 = "
            "'undefined' ORDER BY srs_id",
            nullptr, nullptr)) {
        for (auto& row : *table)
            rows.push_back({row->GetFieldAsInteger64(0), row->GetFieldAsString(1),
                            row->GetFieldAsInteger(2) != 0});
        ds.ReleaseResultSet(table);
    }
    const char* const wkt2_options[] = {"FORMAT=WKT2_2019", nullptr};
    for (const auto& row : rows) {
        OGRSpatialReference from_wkt1;
        const OGRSpatialReference* row_srs = srs;
        if (!row.layers || !srs) {
            if (from_wkt1.importFromWkt(row.wkt1.c_str()) != OGRERR_NONE) continue;
            row_srs = &from_wkt1;
        }
        char* wkt2 = nullptr;
        if (row_srs->exportToWkt(&wkt2, wkt2_options) != OGRERR_NONE || !wkt2) {
            CPLFree(wkt2);
            continue;
        }
        const std::string text = wkt2;
        CPLFree(wkt2);
        execute_sql(ds,
                    "UPDATE gpkg_spatial_ref_sys SET definition_12_063 = " + sql_quoted(text) +
                        " WHERE srs_id = " + std::to_string(row.id),
                    path, errors);
    }
}

}  // namespace terrain::io
