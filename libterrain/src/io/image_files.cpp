// PNG files through GDAL and text through FreeType (image_files.hpp).
#include "image_files.hpp"

#include <ft2build.h>
#include FT_FREETYPE_H
#include <gdal_priv.h>

#include <algorithm>
#include <climits>
#include <map>
#include <memory>
#include <mutex>

#include "gdal_support.hpp"
#include "terrain/core/error.hpp"

namespace terrain::io::detail {
namespace {

// FreeType's library and the faces read so far, behind one lock: a FreeType library and its
// faces serve one thread at a time.
class Fonts {
  public:
    ~Fonts() {
        for (auto& [path, face] : faces_) FT_Done_Face(face);
        if (library_) FT_Done_FreeType(library_);
    }
    std::mutex& mutex() { return mutex_; }
    // The face of `path` (the lock held); throws when FreeType or the file fails.
    FT_Face face(const std::string& path) {
        if (!library_ && FT_Init_FreeType(&library_) != 0) {
            library_ = nullptr;
            throw Error("write", "FreeType cannot start");
        }
        const auto known = faces_.find(path);
        if (known != faces_.end()) return known->second;
        FT_Face face = nullptr;
        if (FT_New_Face(library_, path.c_str(), 0, &face) != 0)
            throw Error("write", "FreeType cannot read the font '" + path + "'");
        return faces_.emplace(path, face).first->second;
    }

  private:
    std::mutex mutex_;
    FT_Library library_ = nullptr;
    std::map<std::string, FT_Face> faces_;
};

Fonts& fonts() {
    static Fonts held;
    return held;
}

// The code points of UTF-8 text; a malformed byte stands for itself.
std::vector<char32_t> code_points(const std::string& text) {
    std::vector<char32_t> out;
    for (std::size_t i = 0; i < text.size();) {
        const auto lead = static_cast<unsigned char>(text[i]);
        const int more = lead >= 0xF0 ? 3 : lead >= 0xE0 ? 2 : lead >= 0xC0 ? 1 : 0;
        char32_t c = more == 0 ? lead : lead & (0x3F >> more);
        bool whole = i + std::size_t(more) < text.size();
        for (int k = 1; whole && k <= more; ++k) {
            const auto next = static_cast<unsigned char>(text[i + std::size_t(k)]);
            whole = (next & 0xC0) == 0x80;
            c = (c << 6) | (next & 0x3F);
        }
        out.push_back(whole ? c : lead);
        i += whole ? std::size_t(more) + 1 : 1;
    }
    return out;
}

// Calls `glyph(pen_x, baseline_y, slot)` for each rendered glyph of `text`, in order.
template <class Glyph>
void each_glyph(FT_Face face, int size, const std::vector<char32_t>& text, Glyph&& glyph) {
    int x = 0, y = 0;
    for (const char32_t c : text) {
        if (c == U'\r') continue;
        if (c == U'\n') {
            x = 0;
            y += size;
            continue;
        }
        if (FT_Load_Char(face, c, FT_LOAD_RENDER) != 0) continue;  // a glyph the font lacks
        glyph(x, y, face->glyph);
        x += static_cast<int>(face->glyph->advance.x >> 6);
    }
}

}  // namespace

void write_image(const std::string& path, const std::string& shown_path, int width, int height,
                 int channels, const std::uint8_t* pixels, int png_compression) {
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4 || !pixels)
        throw Error("write", "cannot write '" + shown_path + "': no pixels");
    ensure_gdal_registered();
    const GdalErrorCapture errors;
    GDALDriver* mem_driver = GetGDALDriverManager()->GetDriverByName("MEM");
    GDALDriver* png_driver = GetGDALDriverManager()->GetDriverByName("PNG");
    if (!mem_driver || !png_driver)
        throw Error("write", "cannot write '" + shown_path + "': GDAL has no PNG driver");
    // The pixels as GDAL bands without a copy: band b starts at byte b, `channels` apart.
    std::unique_ptr<GDALDataset> mem(mem_driver->Create("", width, height, 0, GDT_Byte, nullptr));
    if (!mem) throw Error("write", "cannot write '" + shown_path + "'" + errors.suffix());
    for (int b = 0; b < channels; ++b)
        if (!add_band_in_place(*mem, GDT_Byte, pixels + b, std::size_t(channels),
                               std::size_t(width) * std::size_t(channels)))
            throw Error("write", "cannot write '" + shown_path + "'" + errors.suffix());
    CPLStringList options;
    if (png_compression >= 0)
        options.SetNameValue("ZLEVEL", std::to_string(std::clamp(png_compression, 1, 9)).c_str());
    std::unique_ptr<GDALDataset> png(
        png_driver->CreateCopy(path.c_str(), mem.get(), TRUE, options.List(), nullptr, nullptr));
    if (!png) throw Error("write", "writing '" + shown_path + "' failed" + errors.suffix());
}

TextMask render_text_mask(const std::string& font, int size, const std::string& text) {
    auto& held = fonts();
    const std::lock_guard lock(held.mutex());
    FT_Face face = held.face(font);
    if (FT_Set_Pixel_Sizes(face, 0, static_cast<FT_UInt>(std::max(1, size))) != 0)
        throw Error("write", "FreeType cannot draw the font '" + font + "' at this size");
    const auto points = code_points(text);
    // The box: each glyph's bitmap and one pixel beyond it to the right and below.
    int x0 = INT_MAX, y0 = INT_MAX, x1 = INT_MIN, y1 = INT_MIN;
    each_glyph(face, size, points, [&](int x, int y, FT_GlyphSlot slot) {
        x0 = std::min(x0, x + slot->bitmap_left);
        y0 = std::min(y0, y - slot->bitmap_top);
        x1 = std::max(x1, x + slot->bitmap_left + static_cast<int>(slot->bitmap.width) + 1);
        y1 = std::max(y1, y - slot->bitmap_top + static_cast<int>(slot->bitmap.rows) + 1);
    });
    TextMask out;
    if (x1 <= x0 || y1 <= y0) return out;
    out.x = x0;
    out.y = y0;
    out.width = x1 - x0;
    out.height = y1 - y0;
    out.alpha.assign(static_cast<std::size_t>(out.width) * out.height, 0);
    each_glyph(face, size, points, [&](int x, int y, FT_GlyphSlot slot) {
        const auto& bitmap = slot->bitmap;
        for (int j = 0; j < static_cast<int>(bitmap.rows); ++j)
            for (int i = 0; i < static_cast<int>(bitmap.width); ++i) {
                const int col = x + slot->bitmap_left + i - x0;
                const int row = y - slot->bitmap_top + j - y0;
                out.alpha[static_cast<std::size_t>(row) * out.width + col] =
                    bitmap.buffer[static_cast<std::ptrdiff_t>(j) * bitmap.pitch + i];
            }
    });
    return out;
}

}  // namespace terrain::io::detail
