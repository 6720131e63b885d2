#pragma once
// Private: a planetary CRS restated as the IAU_2015 CRS PROJ's database holds for its body
// (not installed), so that the outputs' CRS has an authority code that projinfo, QGIS and
// geopandas identify and transform (docs/bodies-and-elevation.md).

#include <string>

namespace terrain::geo {

// The CRS `wkt` on the IAU_2015 body of PROJ's database, as single-line WKT2, when its body
// is the Moon (IAU_2015:301xx), Mars (499xx) or Vesta (2000004xx) and its ellipsoid is that
// body's IAU sphere (same radius): a geographic CRS becomes the body's "Sphere / Ocentric"
// CRS (code ..00); a projected one keeps its conversion on that base, and is the database's
// projected CRS itself (with its code) when one is the same (equirectangular or sinusoidal
// centred at 0 or 180, polar, ...). Otherwise (Earth, whose CRSs have EPSG codes; another
// radius; no CRS) `wkt` unchanged.
std::string output_crs_wkt(const std::string& wkt);

}  // namespace terrain::geo
