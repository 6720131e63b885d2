#include "image_module.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <vector>

#include "terrain/core/error.hpp"

namespace terrain::io::detail {
namespace {

using WriteFn = int (*)(const char*, int, int, int, const unsigned char*, int, char*, int);
using InterfaceFn = int (*)();
using TextFn = int (*)(const char*, int, const char*, int*, unsigned char*, int, char*, int);

constexpr const char* kModule = "libterrain_oiio.so";

struct Module {
    WriteFn write = nullptr;
    TextFn text = nullptr;
    std::string path;
    std::string error;  // why it could not be loaded
};

// Places to look: $TERRAIN_OIIO_MODULE alone when it is set; else, in order, beside the
// executable as installed
// (bin/../<libdir>/terrain) and as built (build/<dir>/../lib/terrain); the install directory;
// the build directory (programs built deeper in the tree, such as the benchmarks).
std::vector<std::string> candidates() {
    namespace fs = std::filesystem;
    std::vector<std::string> out;
    if (const char* env = std::getenv("TERRAIN_OIIO_MODULE"); env && *env)
        return {env};  // set: the only place
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        const fs::path dir = exe.parent_path();
        out.push_back((dir / TERRAIN_MODULE_RELATIVE_DIR / kModule).lexically_normal().string());
        out.push_back((dir / ".." / "lib" / "terrain" / kModule).lexically_normal().string());
    }
    out.push_back((fs::path(TERRAIN_MODULE_INSTALL_DIR) / kModule).string());
    out.push_back((fs::path(TERRAIN_MODULE_BUILD_DIR) / kModule).string());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

const Module& module() {
    static const Module m = [] {
        Module r;
        std::string tried;
        for (const auto& path : candidates()) {
            if (!std::filesystem::exists(path)) {
                tried += (tried.empty() ? "" : ", ") + path;
                continue;
            }
            void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
            if (!handle) {
                r.error = std::string("cannot load ") + path + ": " + dlerror();
                return r;
            }
            const auto version =
                reinterpret_cast<InterfaceFn>(dlsym(handle, "terrain_oiio_interface"));
            r.write = reinterpret_cast<WriteFn>(dlsym(handle, "terrain_oiio_write"));
            r.text = reinterpret_cast<TextFn>(dlsym(handle, "terrain_oiio_text"));
            if (!version || version() != 2 || !r.write || !r.text) {
                r.write = nullptr;
                r.text = nullptr;
                r.error = path + " is not this version's OpenImageIO module";
                return r;
            }
            r.path = path;
            return r;
        }
        r.error = std::string("the OpenImageIO module ") + kModule + " was not found (looked at " +
                  tried + "); set TERRAIN_OIIO_MODULE to its path";
        return r;
    }();
    return m;
}

}  // namespace

void write_image(const std::string& path, const std::string& shown_path, int width, int height,
                 int channels, const std::uint8_t* pixels, int png_compression) {
    const Module& m = module();
    if (!m.write) throw Error("write", "cannot write '" + shown_path + "': " + m.error);
    char error[512] = {0};
    if (!m.write(path.c_str(), width, height, channels, pixels, png_compression, error,
                 static_cast<int>(sizeof error)))
        throw Error("write", "writing '" + shown_path + "' failed: " + error);
}

TextMask render_text_mask(const std::string& font, int size, const std::string& text) {
    const Module& m = module();
    if (!m.text) throw Error("write", m.error);
    TextMask out;
    int box[4] = {0, 0, 0, 0};
    char error[512] = {0};
    if (!m.text(font.c_str(), size, text.c_str(), box, nullptr, 0, error,
                static_cast<int>(sizeof error)))
        throw Error("write", error);
    out.x = box[0];
    out.y = box[1];
    out.width = std::max(0, box[2]);
    out.height = std::max(0, box[3]);
    out.alpha.assign(static_cast<std::size_t>(out.width) * out.height, 0);
    if (out.alpha.empty()) return out;
    if (!m.text(font.c_str(), size, text.c_str(), box, out.alpha.data(),
                static_cast<int>(out.alpha.size()), error, static_cast<int>(sizeof error)))
        throw Error("write", error);
    return out;
}

std::string image_module_path() {
    const Module& m = module();
    if (!m.write) throw Error("write", m.error);
    return m.path;
}

}  // namespace terrain::io::detail
