#pragma once
// The body a CRS lies on (Earth, Moon, Mars, Vesta, ...) and its reference ellipsoid. See
// docs/bodies-and-elevation.md.

#include <string>

#include "terrain/core/body.hpp"

namespace terrain::geo {

// The body described by a CRS given as WKT (any flavour GDAL reads, including the WKT GDAL
// builds from PDS labels) or any other definition OGRSpatialReference::SetFromUserInput
// accepts ("EPSG:4326", "IAU_2015:30100", "ESRI:104903"). Empty text: a local metric grid.
// Throws terrain::Error (stage "crs") when the text is not a CRS.
Body body_from_crs(const std::string& crs_definition);

// The canonical body name for a datum/ellipsoid/CRS name and semi-major axis:
// known names first ("D_MOON", "Mars_2000_IAU_IAG", "VESTA"), then the radius.
std::string identify_body_name(const std::string& names, double semi_major_axis);

// The mean radius in metres of a body identify_body_name knows ("Moon": 1737400); 0 for
// another name ("unknown", "none"). For checks that a CRS's radius is plausible.
double known_body_radius(const std::string& name);

}  // namespace terrain::geo
