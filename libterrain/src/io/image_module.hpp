#pragma once
// Private: 8-bit images written through OpenImageIO, loaded on first use from the
// libterrain_oiio.so module (oiio_module.cpp). Not installed.

#include <cstdint>
#include <string>

namespace terrain::io::detail {

// Writes width x height pixels of `channels` interleaved samples to `path` (the format from
// its extension); png_compression is the zlib level of PNG files (-1: the default). Throws
// terrain::Error, naming `shown_path` (the final name of a temporary file), when the module
// cannot be loaded or the file cannot be written.
void write_image(const std::string& path, const std::string& shown_path, int width, int height,
                 int channels, const std::uint8_t* pixels, int png_compression = -1);

// Where the module was loaded from (loading it if needed); throws like write_image.
std::string image_module_path();

}  // namespace terrain::io::detail
