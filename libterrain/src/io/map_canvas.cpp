#include "map_canvas.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <utility>

#include "image_files.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/write_preview.hpp"

namespace terrain::io {
namespace {

std::mutex text_failure_mutex;
std::string text_failure;  // why text could not be drawn with the font found, once

void note_text_failure(const std::string& message) {
    const std::lock_guard<std::mutex> lock(text_failure_mutex);
    if (text_failure.empty()) text_failure = message;
}

}  // namespace

std::string map_text_warning() {
    const std::string font = detail::map_font();
    if (font.empty())
        return "no DejaVu Sans font was found (Debian package fonts-dejavu-core, or set "
               "TERRAIN_FONT to a TrueType file): preview.png and sweep.png are drawn without "
               "text";
    const std::lock_guard<std::mutex> lock(text_failure_mutex);
    if (!text_failure.empty())
        return "the maps' text could not be drawn with " + font + " (" + text_failure +
               "): preview.png and sweep.png are drawn without text";
    return {};
}

namespace detail {

std::string map_font() {
    namespace fs = std::filesystem;
    if (const char* env = std::getenv("TERRAIN_FONT"); env && *env) {
        std::error_code ec;
        return fs::is_regular_file(env, ec) ? std::string(env) : std::string();
    }
    static const char* const places[] = {
        "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",    // Debian, Ubuntu
        "/usr/share/fonts/TTF/DejaVuSans.ttf",                // Arch
        "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",  // Fedora
        "/usr/share/fonts/dejavu/DejaVuSans.ttf",
        "/usr/local/share/fonts/DejaVuSans.ttf",
    };
    for (const char* p : places) {
        std::error_code ec;
        if (fs::is_regular_file(p, ec)) return p;
    }
    return {};
}

std::size_t utf8_length(const std::string& text) {
    return static_cast<std::size_t>(std::count_if(text.begin(), text.end(), [](char c) {
        return (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    }));
}

Canvas::Canvas(int width, int height, Rgba background, std::string font)
    : width_(width), height_(height), font_(std::move(font)) {
    rgba_.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4);
    for (std::size_t i = 0; i < rgba_.size(); i += 4)
        std::copy(background.begin(), background.end(), rgba_.begin() + std::ptrdiff_t(i));
}

Rgba Canvas::pixel(int x, int y) const {
    const auto i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                    static_cast<std::size_t>(x)) *
                   4;
    return {rgba_[i], rgba_[i + 1], rgba_[i + 2], rgba_[i + 3]};
}

void Canvas::blend(int x, int y, Rgba colour, double coverage) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
    const double a = std::clamp(coverage, 0.0, 1.0) * colour[3] / 255.0;
    if (a <= 0) return;
    const auto i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                    static_cast<std::size_t>(x)) *
                   4;
    const double under = rgba_[i + 3] / 255.0;
    const double out = a + under * (1 - a);
    for (int k = 0; k < 3; ++k) {
        const double v =
            (colour[std::size_t(k)] * a + rgba_[i + std::size_t(k)] * under * (1 - a)) /
            std::max(out, 1e-12);
        rgba_[i + std::size_t(k)] =
            static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 255.0)));
    }
    rgba_[i + 3] = static_cast<std::uint8_t>(std::lround(out * 255));
}

void Canvas::fill(int x, int y, int w, int h, Rgba colour) {
    for (int r = std::max(0, y); r < std::min(height_, y + h); ++r)
        for (int c = std::max(0, x); c < std::min(width_, x + w); ++c) blend(c, r, colour);
}

void Canvas::line(double x0, double y0, double x1, double y1, Rgba colour, double thickness) {
    // Coverage from the distance of each pixel centre to the segment (1 px of smoothing).
    const double half = thickness / 2;
    const int c0 = static_cast<int>(std::floor(std::min(x0, x1) - half - 1));
    const int c1 = static_cast<int>(std::ceil(std::max(x0, x1) + half + 1));
    const int r0 = static_cast<int>(std::floor(std::min(y0, y1) - half - 1));
    const int r1 = static_cast<int>(std::ceil(std::max(y0, y1) + half + 1));
    const double dx = x1 - x0, dy = y1 - y0, len2 = dx * dx + dy * dy;
    for (int r = std::max(0, r0); r <= std::min(height_ - 1, r1); ++r)
        for (int c = std::max(0, c0); c <= std::min(width_ - 1, c1); ++c) {
            const double t =
                len2 > 0 ? std::clamp(((c - x0) * dx + (r - y0) * dy) / len2, 0.0, 1.0) : 0;
            const double d = std::hypot(c - (x0 + t * dx), r - (y0 + t * dy));
            blend(c, r, colour, std::clamp(half + 0.5 - d, 0.0, 1.0));
        }
}

void Canvas::triangle(const std::array<double, 2>& a, const std::array<double, 2>& b,
                      const std::array<double, 2>& c, Rgba colour) {
    const int x0 = static_cast<int>(std::floor(std::min({a[0], b[0], c[0]})));
    const int x1 = static_cast<int>(std::ceil(std::max({a[0], b[0], c[0]})));
    const int y0 = static_cast<int>(std::floor(std::min({a[1], b[1], c[1]})));
    const int y1 = static_cast<int>(std::ceil(std::max({a[1], b[1], c[1]})));
    auto edge = [](const std::array<double, 2>& p, const std::array<double, 2>& q, double x,
                   double y) { return (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]); };
    const double area = edge(a, b, c[0], c[1]);
    if (area == 0) return;
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const double e0 = edge(a, b, x, y) / area, e1 = edge(b, c, x, y) / area,
                         e2 = edge(c, a, x, y) / area;
            if (e0 >= 0 && e1 >= 0 && e2 >= 0) blend(x, y, colour);
        }
}

void Canvas::image(const std::uint8_t* rgba, int w, int h, int x, int y) {
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) {
            const std::uint8_t* p = rgba + (static_cast<std::size_t>(r) * w + c) * 4;
            blend(x + c, y + r, {p[0], p[1], p[2], p[3]});
        }
}

// The text is cut into ASCII runs, rendered by FreeType (render_text_mask), and the few other
// characters the figures use, drawn as shapes: the degree sign (a ring), the middle dot (a
// disc), "²" (a small raised 2); "×" is written "x", any other character "?". Spaces at the
// ends of a run are added as DejaVu Sans's advance, 0.318 of the size, since the rendered mask
// ends at the last ink.
struct Canvas::Run {
    enum Kind { ascii, degree, dot, space, squared } kind = ascii;
    TextMask mask;
    double advance = 0;
};

std::vector<Canvas::Run> Canvas::layout(const std::string& text, int size) {
    std::vector<Run> runs;
    std::string ascii;
    auto flush = [&] {
        const auto first = ascii.find_first_not_of(' ');
        const std::size_t lead = first == std::string::npos ? ascii.size() : first;
        const std::size_t trail =
            first == std::string::npos ? 0 : ascii.size() - 1 - ascii.find_last_not_of(' ');
        if (lead) runs.push_back({Run::space, {}, 0.318 * size * double(lead)});
        if (first != std::string::npos) {
            Run run;
            run.mask =
                render_text_mask(font_, size, ascii.substr(lead, ascii.size() - lead - trail));
            run.advance = run.mask.x + run.mask.width + 0.05 * size;
            runs.push_back(std::move(run));
        }
        if (trail) runs.push_back({Run::space, {}, 0.318 * size * double(trail)});
        ascii.clear();
    };
    for (std::size_t i = 0; i < text.size();) {
        const auto byte = static_cast<unsigned char>(text[i]);
        if (byte < 0x80) {
            ascii += text[i++];
            continue;
        }
        std::size_t n = 1;
        while (i + n < text.size() && (static_cast<unsigned char>(text[i + n]) & 0xC0) == 0x80) ++n;
        const std::string character = text.substr(i, n);
        i += n;
        if (character == "\u00b2") {  // a raised "2" at 60 % of the size
            flush();
            Run run;
            run.kind = Run::squared;
            run.mask = render_text_mask(font_, std::max(6, size * 3 / 5), "2");
            run.advance = run.mask.x + run.mask.width + 0.05 * size;
            runs.push_back(std::move(run));
        } else if (character == "\u00d7") {
            ascii += 'x';
        } else if (character == "\u00b0" || character == "\u00b7") {
            flush();
            runs.push_back({character == "\u00b0" ? Run::degree : Run::dot,
                            {},
                            (character == "\u00b0" ? 0.4 : 0.318) * size});
        } else {
            ascii += '?';
        }
    }
    flush();
    return runs;
}

bool Canvas::try_layout(const std::string& text, int size, std::vector<Run>& runs) {
    if (!draws_text()) return false;
    try {
        runs = layout(text, size);
        return true;
    } catch (const Error& e) {
        note_text_failure(e.what());
        font_.clear();
        return false;
    }
}

int Canvas::text_width(const std::string& text, int size) {
    std::vector<Run> runs;
    if (!try_layout(text, size, runs))
        return static_cast<int>(std::lround(0.6 * size * static_cast<double>(utf8_length(text))));
    double width = 0;
    for (const auto& run : runs) width += run.advance;
    return static_cast<int>(std::lround(width));
}

int Canvas::text(int x, int y, const std::string& text, int size, Rgba colour, AlignX align_x,
                 AlignY align_y) {
    std::vector<Run> runs;
    if (!try_layout(text, size, runs)) return text_width(text, size);
    double width = 0;
    for (const auto& run : runs) width += run.advance;
    double pen = x;
    if (align_x == AlignX::centre) pen = x - width / 2;
    if (align_x == AlignX::right) pen = x - width;
    // The baseline: DejaVu's capitals rise 0.73 of the size above it, its descenders 0.24 below.
    int baseline = y;
    if (align_y == AlignY::top) baseline = y + static_cast<int>(std::lround(0.76 * size));
    if (align_y == AlignY::middle) baseline = y + static_cast<int>(std::lround(0.365 * size));
    if (align_y == AlignY::bottom) baseline = y - static_cast<int>(std::lround(0.24 * size));
    for (const auto& run : runs) {
        const int left = static_cast<int>(std::lround(pen));
        if (run.kind == Run::ascii || run.kind == Run::squared) {
            const auto& mask = run.mask;
            const int base =
                baseline - (run.kind == Run::squared ? static_cast<int>(0.38 * size) : 0);
            for (int r = 0; r < mask.height; ++r)
                for (int c = 0; c < mask.width; ++c) {
                    const auto a = mask.alpha[static_cast<std::size_t>(r) * mask.width + c];
                    if (a) blend(left + mask.x + c, base + mask.y + r, colour, a / 255.0);
                }
        } else if (run.kind == Run::degree) {
            disc(pen + 0.2 * size, baseline - 0.6 * size, 0.13 * size, colour,
                 std::max(1.0, 0.075 * size));
        } else if (run.kind == Run::dot) {
            disc(pen + 0.159 * size, baseline - 0.33 * size, std::max(1.0, 0.07 * size), colour, 0);
        }
        pen += run.advance;
    }
    return static_cast<int>(std::lround(width));
}

void Canvas::disc(double cx, double cy, double radius, Rgba colour, double ring) {
    const int x0 = static_cast<int>(std::floor(cx - radius - 1)),
              x1 = static_cast<int>(std::ceil(cx + radius + 1));
    const int y0 = static_cast<int>(std::floor(cy - radius - 1)),
              y1 = static_cast<int>(std::ceil(cy + radius + 1));
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const double d = std::hypot(x - cx, y - cy);
            const double coverage =
                ring > 0 ? ring / 2 + 0.5 - std::abs(d - radius) : radius + 0.5 - d;
            blend(x, y, colour, std::clamp(coverage, 0.0, 1.0));
        }
}

void write_canvas(const Canvas& canvas, const std::string& path, bool overwrite) {
    const int w = canvas.width(), h = canvas.height();
    std::vector<std::uint8_t> rgb(static_cast<std::size_t>(w) * h * 3);  // opaque: no alpha
    for (std::size_t i = 0, n = rgb.size() / 3; i < n; ++i)
        std::copy_n(canvas.rgba().begin() + std::ptrdiff_t(i * 4), 3,
                    rgb.begin() + std::ptrdiff_t(i * 3));
    AtomicOutput output(path, overwrite);
    write_image(output.temp_path(), path, w, h, 3, rgb.data());
    output.commit();
}

}  // namespace detail
}  // namespace terrain::io
