#pragma once
// Writes a DEM as a PDS3 product: a detached label (.LBL) and a raw image (.IMG) of MSB
// 16-bit integers, DN = round((value - OFFSET) / SCALING_FACTOR), NaN as -32768, with an
// IMAGE_MAP_PROJECTION object that GDAL's PDS driver turns back into the same geotransform
// and CRS. The layout of the Dawn HAMO DTM and LRO LOLA LDEM products.

#include <optional>
#include <string>

#include "terrain/core/dem.hpp"

namespace terrain::io {

struct Pds3DemOptions {
    double scaling_factor = 2.0;  // metres per DN (Dawn HAMO DTM: 2)
    // Metres at DN 0; unset: the body's semi-major axis for a radius DEM (255000 for Vesta, as
    // in the HAMO DTM), 0 for heights.
    std::optional<double> offset;
    bool overwrite = false;   // replace an existing label or image
    std::string target_name;  // TARGET_NAME; empty: the DEM's body in upper case ("VESTA")
    std::string product_id;   // PRODUCT_ID; empty: the label's file name without extension
    std::string description;  // DESCRIPTION of the product; empty: a generic one
};

// The image file written beside `label_path`: the same name with extension .IMG (.img when the
// label's extension is lower case).
std::string pds3_image_path(const std::string& label_path);

// Writes `label_path` (which must end in .lbl or .LBL) and its image. The DEM needs a
// north-up geotransform with square pixels and an equirectangular CRS (projected, metres or
// another linear unit) on a sphere or ellipsoid; every valid value must fit in an int16 DN
// (-32767..32767) with the given scaling factor and offset. Both files are written under
// temporary names and renamed when complete. Throws terrain::Error (stage "write") when the
// DEM cannot be written that way, a file exists and `overwrite` is false, or a file cannot
// be written.
void write_pds3_dem(const Dem& dem, const std::string& label_path,
                    const Pds3DemOptions& options = {});

}  // namespace terrain::io
