#pragma once
// The CRS of a synthetic Vesta tile (synth::generate_vesta_tile), as GDAL's PDS driver names
// the CRS of an EQUIRECTANGULAR label for TARGET_NAME = VESTA, so that the tile and its PDS3
// files carry the same CRS.

#include <string>

namespace terrain::io {

// The equirectangular CRS on Vesta's 255 km sphere (WKT2), with the projection's centre
// longitude and latitude of true scale in degrees. Throws terrain::Error (stage "synth") when
// GDAL/PROJ cannot build it.
std::string vesta_equirectangular_wkt(double center_lon, double standard_parallel);

}  // namespace terrain::io
