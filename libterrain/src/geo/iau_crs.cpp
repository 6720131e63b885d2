#include "terrain/internal/geo/iau_crs.hpp"

#include <ogr_spatialref.h>
#include <proj.h>

#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string_view>

#include "terrain/geo/body.hpp"

namespace terrain::geo {
namespace {

struct IauBody {
    std::string_view name;
    long long code;  // the body's NAIF id: IAU_2015 codes are id * 100 + kind
};
constexpr IauBody kIauBodies[] = {{"Moon", 301}, {"Mars", 499}, {"Vesta", 2000004}};

// PROJ's context of this thread, its messages silenced (a code the database lacks is an
// answer here, not an error).
PJ_CONTEXT* projection_context() {
    struct Context {
        PJ_CONTEXT* context = proj_context_create();
        Context() { proj_log_level(context, PJ_LOG_NONE); }
        ~Context() { proj_context_destroy(context); }
    };
    thread_local Context held;
    return held.context;
}

// The IAU_2015 CRS of a code, read from PROJ's database by its code. Not through
// OGRSpatialReference::SetFromUserInput("IAU_2015:N"), which first lists every authority of
// the database: a query of 30 to 50 ms, made for each of the up to 17 codes a CRS is
// compared with.
std::unique_ptr<OGRSpatialReference> from_database(long long code) {
    PJ_CONTEXT* context = projection_context();
    PJ* crs = proj_create_from_database(context, "IAU_2015", std::to_string(code).c_str(),
                                        PJ_CATEGORY_CRS, 0, nullptr);
    if (crs == nullptr) return nullptr;
    const char* wkt = proj_as_wkt(context, crs, PJ_WKT2_2019, nullptr);
    auto srs = std::make_unique<OGRSpatialReference>();
    const bool read = wkt != nullptr && srs->importFromWkt(wkt) == OGRERR_NONE;
    proj_destroy(crs);
    if (!read) return nullptr;
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

std::string restate_on_iau_body(const std::string& wkt) {
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

}  // namespace

// Each output file of a run restates the DEM's CRS (five or six times a run, 10 to 40 ms
// each): the answers are kept for the process.
std::string output_crs_wkt(const std::string& wkt) {
    if (wkt.empty()) return wkt;
    static std::mutex mutex;
    static std::map<std::string, std::string> known;
    const std::lock_guard lock(mutex);
    const auto at = known.find(wkt);
    if (at != known.end()) return at->second;
    return known.emplace(wkt, restate_on_iau_body(wkt)).first->second;
}

}  // namespace terrain::geo
