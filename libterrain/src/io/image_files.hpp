#pragma once
// Private: 8-bit PNG images written through GDAL's PNG driver, and text drawn by FreeType.
// Both libraries are in the process already (GDAL links FreeType), so writing a figure loads
// nothing more. Not installed.

#include <cstdint>
#include <string>
#include <vector>

namespace terrain::io::detail {

// Writes width x height pixels of `channels` (1 to 4) interleaved samples to `path` as PNG;
// png_compression is the zlib level (-1: GDAL's default, 6). Throws terrain::Error, naming
// `shown_path` (the final name of a temporary file), when the file cannot be written.
void write_image(const std::string& path, const std::string& shown_path, int width, int height,
                 int channels, const std::uint8_t* pixels, int png_compression = -1);

// Text drawn by FreeType: a coverage mask (0-255) of `width` x `height` pixels whose
// top-left corner lies at (x, y) from the left end of the first baseline.
struct TextMask {
    int x = 0, y = 0, width = 0, height = 0;
    std::vector<std::uint8_t> alpha;
};
// `text` (UTF-8, '\n' starts a line `size` pixels lower) in the font file `font`, `size`
// pixels high. Each glyph is FreeType's rendering at the pen position, the pen moving by the
// glyph's advance in whole pixels; where glyphs overlap, the later one's coverage is kept;
// the mask reaches one pixel beyond each glyph's bitmap to the right and below. Throws
// terrain::Error when the font cannot be read.
TextMask render_text_mask(const std::string& font, int size, const std::string& text);

}  // namespace terrain::io::detail
