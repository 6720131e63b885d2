#include "terrain/internal/geo/iau_crs.hpp"

#include <ogr_spatialref.h>

#include <cmath>
#include <memory>
#include <string_view>

#include "terrain/geo/body.hpp"

namespace terrain::geo {
namespace {

struct IauBody {
    std::string_view name;
    long long code;  // the body's NAIF id: IAU_2015 codes are id * 100 + kind
};
constexpr IauBody kIauBodies[] = {{"Moon", 301}, {"Mars", 499}, {"Vesta", 2000004}};

std::unique_ptr<OGRSpatialReference> from_database(long long code) {
    auto srs = std::make_unique<OGRSpatialReference>();
    const std::string name = "IAU_2015:" + std::to_string(code);
    if (srs->SetFromUserInput(name.c_str()) != OGRERR_NONE) return nullptr;
    srs->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    return srs;
}

std::string single_line_wkt2(const OGRSpatialReference& srs) {
    const char* options[] = {"FORMAT=WKT2_2019", "MULTILINE=NO", nullptr};
    char* text = nullptr;
    if (srs.exportToWkt(&text, options) != OGRERR_NONE) {
        CPLFree(text);
        return {};
    }
    std::string out = text ? text : "";
    CPLFree(text);
    return out;
}

}  // namespace

std::string output_crs_wkt(const std::string& wkt) {
    if (wkt.empty()) return wkt;
    OGRSpatialReference source;
    if (source.SetFromUserInput(wkt.c_str()) != OGRERR_NONE) return wkt;
    if (!source.IsGeographic() && !source.IsProjected()) return wkt;
    const Body body = body_from_crs(wkt);
    long long code = 0;
    for (const auto& b : kIauBodies)
        if (body.name == b.name) code = b.code;
    if (code == 0) return wkt;
    const auto sphere = from_database(code * 100);
    if (!sphere) return wkt;
    OGRErr error = OGRERR_NONE;
    const double a = source.GetSemiMajor(&error);
    if (error != OGRERR_NONE || source.GetInvFlattening() != 0 ||
        std::abs(a - sphere->GetSemiMajor()) > 1e-9 * a)
        return wkt;
    if (source.IsGeographic()) {
        // Lon/lat in degrees on the sphere, longitude first: the IAU CRS itself.
        if (source.GetAngularUnits() != sphere->GetAngularUnits()) return wkt;
        const auto out = single_line_wkt2(*sphere);
        return out.empty() ? wkt : out;
    }
    OGRSpatialReference restated(source);
    if (restated.CopyGeogCSFrom(sphere.get()) != OGRERR_NONE) return wkt;
    // The projected CRSs of the body: kinds 10, 15, ..., 85.
    for (long long kind = 10; kind <= 85; kind += 5) {
        const auto candidate = from_database(code * 100 + kind);
        if (candidate && restated.IsSame(candidate.get())) {
            const auto out = single_line_wkt2(*candidate);
            if (!out.empty()) return out;
        }
    }
    const auto out = single_line_wkt2(restated);
    return out.empty() ? wkt : out;
}

}  // namespace terrain::geo
