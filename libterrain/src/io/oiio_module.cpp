// The OpenImageIO module (libterrain_oiio.so): the only code that links OpenImageIO. Debian's
// OpenImageIO pulls in a few hundred shared libraries (start-up time and resident memory of
// their own), so libterrain loads this module with dlopen only when it writes an image
// (image_module.cpp). A C interface keeps the two sides independent of each other's ABI.
// Text on the figures is drawn here too: OpenImageIO renders it with FreeType
// (ImageBufAlgo::render_text) from a font file libterrain finds at run time (map_canvas.cpp).

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstring>
#include <exception>
#include <string>

namespace {

void set_error(const std::string& message, char* error, int error_size) {
    if (!error || error_size <= 0) return;
    const std::size_t n = std::min(message.size(), static_cast<std::size_t>(error_size - 1));
    std::memcpy(error, message.data(), n);
    error[n] = '\0';
}

}  // namespace

extern "C" {

// The interface version libterrain checks before using the module.
__attribute__((visibility("default"))) int terrain_oiio_interface() {
    return 2;
}

// Writes width x height pixels of `channels` interleaved 8-bit samples to `path` in the format
// of its extension. png_compression: zlib level for PNG files (-1: OpenImageIO's default).
// Returns 1 on success, 0 with a message in `error`.
__attribute__((visibility("default"))) int terrain_oiio_write(const char* path, int width,
                                                              int height, int channels,
                                                              const unsigned char* pixels,
                                                              int png_compression, char* error,
                                                              int error_size) {
    try {
        auto out = OIIO::ImageOutput::create(path);
        if (!out) {
            set_error("OpenImageIO cannot write this format: " + OIIO::geterror(), error,
                      error_size);
            return 0;
        }
        OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
        if (png_compression >= 0) spec.attribute("png:compressionLevel", png_compression);
        if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::UINT8, pixels) ||
            !out->close()) {
            set_error(out->geterror(), error, error_size);
            return 0;
        }
        return 1;
    } catch (const std::exception& e) {
        set_error(e.what(), error, error_size);
        return 0;
    }
}

// Text in the font file `font` with a nominal height of `size` pixels, as a coverage mask (0 to
// 255, one byte per pixel, row-major). box receives {x, y, width, height}: the mask's top-left
// corner relative to the left end of the first line's baseline, and its size. With mask null
// only box is filled; otherwise the mask must hold mask_size >= width * height bytes. Returns
// 1 on success, 0 with a message in `error` (no FreeType in this OpenImageIO, unreadable font).
__attribute__((visibility("default"))) int terrain_oiio_text(const char* font, int size,
                                                             const char* text, int* box,
                                                             unsigned char* mask, int mask_size,
                                                             char* error, int error_size) {
    try {
        const OIIO::ROI extent = OIIO::ImageBufAlgo::text_size(text, size, font);
        if (!extent.defined()) {
            set_error("OpenImageIO cannot render text with the font '" + std::string(font) +
                          "': " + OIIO::geterror(),
                      error, error_size);
            return 0;
        }
        box[0] = extent.xbegin;
        box[1] = extent.ybegin;
        box[2] = extent.width();
        box[3] = extent.height();
        if (!mask) return 1;
        if (mask_size < box[2] * box[3]) {
            set_error("the text mask is too small", error, error_size);
            return 0;
        }
        OIIO::ImageBuf image(OIIO::ImageSpec(box[2], box[3], 1, OIIO::TypeDesc::FLOAT));
        const float one = 1.f;
        if (!OIIO::ImageBufAlgo::zero(image) ||
            !OIIO::ImageBufAlgo::render_text(image, -extent.xbegin, -extent.ybegin, text, size,
                                             font, OIIO::cspan<float>(&one, 1)) ||
            !image.get_pixels(image.roi(), OIIO::TypeDesc::UINT8, mask)) {
            set_error(image.geterror(), error, error_size);
            return 0;
        }
        return 1;
    } catch (const std::exception& e) {
        set_error(e.what(), error, error_size);
        return 0;
    }
}

}  // extern "C"
