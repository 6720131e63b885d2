// The OpenImageIO module (libterrain_oiio.so): the only code that links OpenImageIO. Debian's
// OpenImageIO pulls in about 260 shared libraries (a quarter of a second and 90 MiB resident
// at start-up), so libterrain loads this module with dlopen only when it writes an image
// (image_module.cpp). A C interface keeps the two sides independent of each other's ABI.

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
    return 1;
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

}  // extern "C"
