#pragma once
// The body a DEM lies on (Earth, Moon, Mars, Vesta, ...) and its reference ellipsoid,
// identified from the raster's CRS. See docs/bodies-and-elevation.md.

#include <string>

namespace terrain {

struct Body {
    std::string name;            // "Moon", "Mars", ...; "unknown" or "none" otherwise
    double semi_major_axis = 0;  // metres; 0 for a local grid with no CRS
    double flattening = 0;       // (a - b) / a; 0 for a sphere
    bool has_crs = false;        // false: a local metric grid, no body

    double semi_minor_axis() const { return semi_major_axis * (1 - flattening); }
    bool is_local_grid() const { return !has_crs; }
};

// The body described by a CRS given as WKT (any flavour GDAL reads, including the WKT GDAL
// builds from PDS labels) or any other definition OGRSpatialReference::SetFromUserInput
// accepts ("EPSG:4326", "IAU_2015:30100", "ESRI:104903"). Empty text: a local metric grid.
// Throws terrain::Error when the text is not a CRS.
Body body_from_crs(const std::string& crs_definition);

// The canonical body name for a datum/ellipsoid/CRS name and semi-major axis:
// known names first ("D_MOON", "Mars_2000_IAU_IAG", "VESTA"), then the radius.
std::string identify_body_name(const std::string& names, double semi_major_axis);

}  // namespace terrain
