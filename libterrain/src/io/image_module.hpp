#pragma once
// Private: 8-bit images written through OpenImageIO, loaded on first use from the
// libterrain_oiio.so module (oiio_module.cpp). Not installed.

#include <cstdint>
#include <string>
#include <vector>

namespace terrain::io::detail {

// Writes width x height pixels of `channels` interleaved samples to `path` (the format from
// its extension); png_compression is the zlib level of PNG files (-1: the default). Throws
// terrain::Error, naming `shown_path` (the final name of a temporary file), when the module
// cannot be loaded or the file cannot be written.
void write_image(const std::string& path, const std::string& shown_path, int width, int height,
                 int channels, const std::uint8_t* pixels, int png_compression = -1);

// Text drawn by FreeType through OpenImageIO: a coverage mask (0-255) of `width` x `height`
// pixels whose top-left corner lies at (x, y) from the left end of the first baseline.
struct TextMask {
    int x = 0, y = 0, width = 0, height = 0;
    std::vector<std::uint8_t> alpha;
};
// `text` (UTF-8, '\n' starts a line) in the font file `font`, `size` pixels high. Throws
// terrain::Error when the module cannot be loaded or cannot render with that font.
TextMask render_text_mask(const std::string& font, int size, const std::string& text);

// Where the module was loaded from (loading it if needed); throws like write_image.
std::string image_module_path();

}  // namespace terrain::io::detail
