#pragma once
// preview.png: a picture of one segmentation of a DEM (docs/outputs.md). Like every writer of
// io/: atomic, refuses an existing file unless `overwrite`, throws one terrain::Error (stage
// "write") on failure, and writes the same bytes for the same input.

#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/dem.hpp"

namespace terrain::io {

// Hillshade of the DEM blended with the field's colour map (blue concave, white flat, red
// convex on [0,100]), region boundaries in black, NoData transparent; scaled by an integer
// factor (nearest neighbour) to about 1024 pixels on the long side, or reduced to at most
// 4096. `field_pixels`: field::field_to_pixels() of the DEM; `pixels`: segment::label_pixels()
// of the DEM (row-major, 0 = no region).
void write_preview_png(const Dem& dem, const std::vector<float>& field_pixels,
                       const std::vector<std::uint32_t>& pixels, const std::string& path,
                       bool overwrite);

// The preview in two steps: its pixels (8-bit RGBA, row-major), then the PNG. Writing goes
// through OpenImageIO, loaded on first use (about 120 MB resident, a quarter of a second): a
// program low on memory renders first, frees its large data, then writes.
struct PreviewImage {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgba;
};
PreviewImage render_preview(const Dem& dem, const std::vector<float>& field_pixels,
                            const std::vector<std::uint32_t>& pixels);
void write_preview_image(const PreviewImage& image, const std::string& path, bool overwrite);

}  // namespace terrain::io
