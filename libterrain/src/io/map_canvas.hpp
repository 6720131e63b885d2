#pragma once
// Private: an 8-bit RGBA canvas for the figures io writes (preview.png's map frame, sweep.png):
// rectangles, lines, images and text. Text is drawn by FreeType (image_files.hpp) in a font
// found at run time (map_font); without one the figure is drawn without text. Not installed.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace terrain::io::detail {

using Rgba = std::array<std::uint8_t, 4>;

// The font file of the figures' text: $TERRAIN_FONT when set (a path to a TrueType file), else
// the first of DejaVu Sans's usual places (Debian's fonts-dejavu-core installs
// /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf). Empty when there is none.
std::string map_font();

enum class AlignX { left, centre, right };
enum class AlignY { baseline, top, middle, bottom };

class Canvas {
  public:
    // `font`: the font file, or empty to draw no text.
    Canvas(int width, int height, Rgba background, std::string font);

    int width() const { return width_; }
    int height() const { return height_; }
    const std::vector<std::uint8_t>& rgba() const { return rgba_; }
    std::vector<std::uint8_t>& rgba() { return rgba_; }
    Rgba pixel(int x, int y) const;
    // True while text can be drawn: a font was given and rendering with it has not failed.
    bool draws_text() const { return !font_.empty(); }

    // `colour` over the pixel with opacity `coverage` (0..1); outside the canvas: nothing.
    void blend(int x, int y, Rgba colour, double coverage = 1);
    void fill(int x, int y, int w, int h, Rgba colour);
    // A line `thickness` pixels wide between two points (pixel centres).
    void line(double x0, double y0, double x1, double y1, Rgba colour, double thickness = 1);
    // A filled triangle.
    void triangle(const std::array<double, 2>& a, const std::array<double, 2>& b,
                  const std::array<double, 2>& c, Rgba colour);
    // An RGBA image with its top-left corner at (x, y), composited by its alpha.
    void image(const std::uint8_t* rgba, int w, int h, int x, int y);

    // A disc of `radius` pixels centred at (cx, cy), or a ring `ring` pixels wide when ring > 0.
    void disc(double cx, double cy, double radius, Rgba colour, double ring = 0);

    // Text `size` pixels high anchored at (x, y); returns its width in pixels (also when no
    // font draws it: then estimated). AlignY::middle centres the height of a capital.
    int text(int x, int y, const std::string& text, int size, Rgba colour,
             AlignX align_x = AlignX::left, AlignY align_y = AlignY::baseline);
    // The width `text` would take: measured with the font, estimated without one.
    int text_width(const std::string& text, int size);

  private:
    struct Run;
    std::vector<Run> layout(const std::string& text, int size);
    bool try_layout(const std::string& text, int size, std::vector<Run>& runs);

    int width_, height_;
    std::vector<std::uint8_t> rgba_;
    std::string font_;
};

// A UTF-8 string's code points (for width estimates).
std::size_t utf8_length(const std::string& text);

// The canvas as an opaque RGB image file (PNG from the extension), written atomically:
// refused when `path` exists unless `overwrite` (terrain::Error, stage "write").
void write_canvas(const Canvas& canvas, const std::string& path, bool overwrite);

}  // namespace terrain::io::detail
