#pragma once
// The CRS of a synthetic Vesta tile (generate_vesta_tile), as GDAL's PDS driver names the CRS
// of an EQUIRECTANGULAR label for TARGET_NAME = VESTA, so that the tile and its PDS3 files
// carry the same CRS.

#include <string>

namespace terrain::synth {

// The equirectangular CRS on Vesta's 255 km sphere as WKT2 (2019), with the projection's
// centre longitude and latitude of true scale in degrees: the text GDAL's OGR exports for it
// (tests/synth/vesta_crs.cpp compares the two), written here so that synth needs no GDAL.
std::string vesta_equirectangular_wkt(double center_lon, double standard_parallel);

}  // namespace terrain::synth
