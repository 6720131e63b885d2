#include "terrain/internal/geo/ogr_support.hpp"

namespace terrain::geo {

LonLatTransform make_lonlat_transform(const std::string& crs) {
    LonLatTransform t;
    t.source = std::make_unique<OGRSpatialReference>();
    if (t.source->SetFromUserInput(crs.c_str()) != OGRERR_NONE) return t;
    t.source->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    t.geographic.reset(t.source->CloneGeogCS());
    if (!t.geographic) return t;
    t.geographic->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    t.to_lonlat.reset(OGRCreateCoordinateTransformation(t.source.get(), t.geographic.get()));
    return t;
}

GdalErrorCapture::GdalErrorCapture() {
    CPLPushErrorHandlerEx(&GdalErrorCapture::handler, this);
}

GdalErrorCapture::~GdalErrorCapture() {
    CPLPopErrorHandler();
}

void CPL_STDCALL GdalErrorCapture::handler(CPLErr level, CPLErrorNum, const char* message) {
    if (level < CE_Failure || !message) return;
    auto* self = static_cast<GdalErrorCapture*>(CPLGetErrorHandlerUserData());
    if (!self) return;
    // One line: GDAL's messages may span several (a PDS label naming a missing image).
    self->last_error_ = message;
    for (char& c : self->last_error_)
        if (c == '\n' || c == '\r') c = ' ';
    while (!self->last_error_.empty() && self->last_error_.back() == ' ')
        self->last_error_.pop_back();
}

}  // namespace terrain::geo
