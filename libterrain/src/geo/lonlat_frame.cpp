#include "terrain/internal/geo/lonlat_frame.hpp"

#include <cpl_conv.h>

#include <cmath>
#include <vector>

#include "terrain/core/error.hpp"

namespace terrain::geo {

LonLatFrame::LonLatFrame(const Dem& dem, const char* stage)
    : LonLatFrame(dem.crs_wkt, dem.body.name == "Earth",
                  dem.map_xy(dem.width / 2.0, dem.height / 2.0), stage) {}

LonLatFrame::LonLatFrame(const std::string& crs_wkt, bool earth, std::array<double, 2> centre,
                         const char* stage) {
    if (crs_wkt.empty()) throw Error(stage, "the DEM has no CRS, so no longitude/latitude");
    source_ = std::make_unique<OGRSpatialReference>();
    if (source_->SetFromUserInput(crs_wkt.c_str()) != OGRERR_NONE)
        throw Error(stage, "cannot read the DEM's CRS");
    source_->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    earth_ = earth;
    if (earth_) {
        target_ = std::make_unique<OGRSpatialReference>();
        target_->importFromEPSG(4326);
    } else {
        target_.reset(source_->CloneGeogCS());
        if (!target_) throw Error(stage, "the DEM's CRS has no geographic CRS");
    }
    target_->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    to_lonlat_.reset(OGRCreateCoordinateTransformation(source_.get(), target_.get()));
    if (!to_lonlat_)
        throw Error(stage, "cannot transform the DEM's CRS to longitude/latitude on its body");
    int ok = 0;
    if (!to_lonlat_->Transform(1, &centre[0], &centre[1], nullptr, &ok) || !ok)
        throw Error(stage, "the centre of the DEM has no longitude/latitude");
    centre_lon_ = centre[0];
}

std::string LonLatFrame::wkt() const {
    const char* options[] = {"FORMAT=WKT2_2019", "MULTILINE=NO", nullptr};
    char* text = nullptr;
    target_->exportToWkt(&text, options);
    std::string out = text ? text : "";
    CPLFree(text);
    return out;
}

std::string geojson_crs_name(const std::string& wkt) {
    OGRSpatialReference srs;
    if (wkt.empty() || srs.SetFromUserInput(wkt.c_str()) != OGRERR_NONE) return "";
    const char* authority = srs.GetAuthorityName(nullptr);
    const char* code = srs.GetAuthorityCode(nullptr);
    if (!authority || !code) return wkt;
    if (std::string(authority) == "EPSG" && std::string(code) == "4326") return "";
    return std::string("urn:ogc:def:crs:") + authority + "::" + code;
}

bool LonLatFrame::transform(std::size_t count, double* x, double* y) const {
    if (count == 0) return true;
    std::vector<int> ok(count, 0);
    if (!to_lonlat_->Transform(count, x, y, nullptr, ok.data())) return false;
    for (std::size_t i = 0; i < count; ++i) {
        if (!ok[i] || !std::isfinite(x[i]) || !std::isfinite(y[i])) return false;
        x[i] = centre_lon_ + std::remainder(x[i] - centre_lon_, 360.0);
    }
    return true;
}

bool LonLatFrame::transform(std::size_t count, double* x, double* y, std::uint8_t* ok) const {
    if (count == 0) return true;
    std::vector<int> done(count, 0);
    const bool any = to_lonlat_->Transform(count, x, y, nullptr, done.data());
    bool all = any;
    for (std::size_t i = 0; i < count; ++i) {
        const bool good = any && done[i] && std::isfinite(x[i]) && std::isfinite(y[i]);
        if (good) x[i] = centre_lon_ + std::remainder(x[i] - centre_lon_, 360.0);
        if (ok) ok[i] = good;
        all = all && good;
    }
    return all;
}

}  // namespace terrain::geo
