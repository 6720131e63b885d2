// preview.png's frame around the map: the graticule's ticks and labels, the title, the
// colour bar, the north arrow, the scale bar and the caption, drawn on a map_canvas.hpp Canvas
// from the frame's values (write_preview.cpp's map_frame).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "map_canvas.hpp"
#include "terrain/io/write_preview.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// 1, 2 or 5 times a power of ten, at most `limit`.
double round_length(double limit) {
    const double magnitude = std::pow(10.0, std::floor(std::log10(limit)));
    for (const double m : {5.0, 2.0, 1.0})
        if (m * magnitude <= limit) return m * magnitude;
    return magnitude;
}

std::string length_text(double metres) {
    char text[32];
    if (metres >= 1000)
        std::snprintf(text, sizeof text, "%g km", metres / 1000);
    else
        std::snprintf(text, sizeof text, "%g m", metres);
    return text;
}

using detail::AlignX;
using detail::AlignY;
using detail::Canvas;
using detail::Rgba;

// The sizes of a framed preview: the map, the font sizes, padding and ticks, the colour bar
// and the north arrow, the right panel's height.
struct FrameLayout {
    int W = 0, H = 0;
    int f = 0, small = 0, pad = 0, tick = 0;
    int bar_w = 0, bar_h = 0, arrow = 0, panel_h = 0;
    Rgba ink{25, 25, 25, 255}, white{255, 255, 255, 255};
};

// The colour bar's labels and their values: the landform classes, or 0 to 100.
struct BarLabels {
    std::vector<std::string> labels;
    std::vector<double> values;
};

BarLabels bar_labels_of(const MapFrame& frame) {
    BarLabels out;
    std::vector<std::string>& bar_labels = out.labels;
    std::vector<double>& bar_values = out.values;
    if (frame.landform_classes)
        for (int k = 0; k < 9; ++k) {
            bar_labels.push_back(segment::to_string(static_cast<segment::Landform>(k)));
            bar_values.push_back(segment::landform_centre(static_cast<segment::Landform>(k)));
        }
    else
        for (int k = 0; k <= 4; ++k) {
            bar_labels.push_back(std::to_string(25 * k));
            bar_values.push_back(25.0 * k);
        }
    return out;
}

// The caption's items joined with " · " into lines no wider than `room`.
std::vector<std::string> caption_lines(const MapFrame& frame, Canvas& measure, int room,
                                       int small) {
    std::vector<std::string> lines;
    std::string line;
    for (const auto& item : frame.caption) {
        const std::string longer = line.empty() ? item : line + " · " + item;
        if (!line.empty() && measure.text_width(longer, small) > room) {
            lines.push_back(line);
            line = item;
        } else {
            line = longer;
        }
    }
    if (!line.empty()) lines.push_back(line);
    return lines;
}

// The map in its frame (NoData left transparent) and the graticule's ticks and labels.
void draw_map(Canvas& c, const PreviewImage& image, const FramedMap& out, const FrameLayout& L,
              int canvas_w) {
    const MapFrame& frame = image.frame;
    const int W = L.W, H = L.H, f = L.f, small = L.small, tick = L.tick;
    const Rgba ink = L.ink;
    // The map in its frame, NoData left transparent.
    for (int y = 0; y < H; ++y)
        std::copy_n(image.rgba.begin() + std::ptrdiff_t(std::size_t(y) * W * 4), std::size_t(W) * 4,
                    c.rgba().begin() +
                        std::ptrdiff_t(
                            (std::size_t(out.map_y + y) * canvas_w + std::size_t(out.map_x)) * 4));
    c.fill(out.map_x - 1, out.map_y - 1, W + 2, 1, ink);
    c.fill(out.map_x - 1, out.map_y + H, W + 2, 1, ink);
    c.fill(out.map_x - 1, out.map_y - 1, 1, H + 2, ink);
    c.fill(out.map_x + W, out.map_y - 1, 1, H + 2, ink);
    for (const auto& t : frame.ticks) {
        const int p = static_cast<int>(std::lround(t.position));
        switch (t.edge) {
            case 0:
                c.fill(out.map_x + p, out.map_y - 1 - tick, 1, tick, ink);
                break;
            case 2:
                c.fill(out.map_x + p, out.map_y + H + 1, 1, tick, ink);
                c.text(out.map_x + p, out.map_y + H + 1 + tick + small / 4, t.label, small, ink,
                       AlignX::centre, AlignY::top);
                break;
            case 3:
                c.fill(out.map_x - 1 - tick, out.map_y + p, tick, 1, ink);
                c.text(out.map_x - 1 - tick - f / 4, out.map_y + p, t.label, small, ink,
                       AlignX::right, AlignY::middle);
                break;
            default:
                c.fill(out.map_x + W + 1, out.map_y + p, tick, 1, ink);
        }
    }
}

// The colour bar: 100 at the top, class boundaries and names on its right.
void draw_colour_bar(Canvas& c, const FramedMap& out, const FrameLayout& L,
                     const std::string& bar_title, const BarLabels& bar, bool landform_classes) {
    const int f = L.f, small = L.small, bar_w = L.bar_w, bar_h = L.bar_h;
    const Rgba ink = L.ink;
    c.text(out.bar_x, out.map_y + f, bar_title, small, ink, AlignX::left, AlignY::middle);
    for (int r = 0; r < bar_h; ++r) {
        const auto colour = preview_field_colour(100.0 * (1 - (r + 0.5) / bar_h));
        c.fill(out.bar_x, out.bar_y + r, bar_w, 1, {colour[0], colour[1], colour[2], 255});
    }
    auto bar_row = [&](double value) {
        return out.bar_y + static_cast<int>(std::lround((1 - value / 100) * bar_h));
    };
    c.fill(out.bar_x - 1, out.bar_y - 1, bar_w + 2, 1, ink);
    c.fill(out.bar_x - 1, out.bar_y + bar_h, bar_w + 2, 1, ink);
    c.fill(out.bar_x - 1, out.bar_y - 1, 1, bar_h + 2, ink);
    c.fill(out.bar_x + bar_w, out.bar_y - 1, 1, bar_h + 2, ink);
    if (landform_classes)
        for (int k = 1; k < 9; ++k)  // class boundaries: 6.25, 18.75, ..., 93.75
            c.fill(out.bar_x + bar_w, bar_row(6.25 + 12.5 * (k - 1)), f / 3, 1, ink);
    for (std::size_t k = 0; k < bar.labels.size(); ++k) {
        const int row = bar_row(bar.values[k]);
        if (!landform_classes) c.fill(out.bar_x + bar_w, row, f / 3, 1, ink);
        c.text(out.bar_x + bar_w + f / 2, row, bar.labels[k], small, ink, AlignX::left,
               AlignY::middle);
    }
}

// The north arrow below the colour bar, pointing `north_degrees` from up.
void draw_north_arrow(Canvas& c, const FramedMap& out, const FrameLayout& L, double north_degrees) {
    const int f = L.f, bar_w = L.bar_w, bar_h = L.bar_h, arrow = L.arrow;
    const Rgba ink = L.ink;
    const double cx = out.bar_x + bar_w / 2.0, cy = out.bar_y + bar_h + 3 * f + arrow / 2.0;
    const double a = north_degrees * kDegree;
    const double ux = std::sin(a), uy = -std::cos(a);  // towards north
    const double half = arrow / 2.0;
    const std::array<double, 2> tip{cx + ux * half, cy + uy * half};
    const std::array<double, 2> back{cx - ux * half, cy - uy * half};
    const std::array<double, 2> base{cx + ux * (half - f), cy + uy * (half - f)};
    c.line(back[0], back[1], base[0], base[1], ink, std::max(2, f / 6));
    c.triangle(tip, {base[0] - uy * f * 0.45, base[1] + ux * f * 0.45},
               {base[0] + uy * f * 0.45, base[1] - ux * f * 0.45}, ink);
    c.text(static_cast<int>(std::lround(tip[0] + ux * f * 0.7)),
           static_cast<int>(std::lround(tip[1] + uy * f * 0.7)), "N", f, ink, AlignX::centre,
           AlignY::middle);
}

// The scale bar at height y: four segments, black and white, its length and the scale's
// note. Returns the height below it.
int draw_scale_bar(Canvas& c, Canvas& measure, const MapFrame& frame, const FramedMap& out,
                   const FrameLayout& L, int y) {
    const int W = L.W, f = L.f, small = L.small;
    const Rgba ink = L.ink, white = L.white;
    const double length_m = round_length(0.3 * W * frame.metres_per_pixel);
    const int length = static_cast<int>(std::lround(length_m / frame.metres_per_pixel));
    const int x0 = out.map_x, bar_y = y + f / 2, h = std::max(4, f / 3);
    for (int k = 0; k < 4; ++k) {
        const int a = x0 + length * k / 4, b = x0 + length * (k + 1) / 4;
        c.fill(a, bar_y, b - a, h, k % 2 ? white : ink);
    }
    c.fill(x0, bar_y, length, 1, ink);
    c.fill(x0, bar_y + h - 1, length, 1, ink);
    c.fill(x0, bar_y, 1, h, ink);
    c.fill(x0 + length - 1, bar_y, 1, h, ink);
    c.text(x0, bar_y + h + small / 4, "0", small, ink, AlignX::centre, AlignY::top);
    c.text(x0 + length, bar_y + h + small / 4, length_text(length_m), small, ink, AlignX::centre,
           AlignY::top);
    const int after = x0 + length + measure.text_width(length_text(length_m), small) / 2 + f;
    c.text(after, bar_y + h / 2, frame.scale_note, small, ink, AlignX::left, AlignY::middle);
    y += 3 * f;
    return y;
}

}  // namespace

FramedMap frame_preview(const PreviewImage& image) {
    const MapFrame& frame = image.frame;
    FrameLayout L;
    L.W = image.width, L.H = image.height;
    const int W = L.W, H = L.H;
    const int f = std::clamp(static_cast<int>(std::lround(std::max(W, H) / 64.0)), 13, 28);
    const int small = std::max(11, f * 7 / 8);
    const int pad = f, tick = std::max(4, f / 2);
    L.f = f, L.small = small, L.pad = pad, L.tick = tick;
    const std::string font = detail::map_font();
    Canvas measure(1, 1, {255, 255, 255, 255}, font);
    const Rgba ink = L.ink, white = L.white;

    // Left: the latitudes' labels; bottom edge: the longitudes'.
    int left_labels = 0;
    for (const auto& t : frame.ticks)
        if (t.edge == 3) left_labels = std::max(left_labels, measure.text_width(t.label, small));
    // Right panel: the colour bar, its labels and title, the north arrow.
    const BarLabels bar = bar_labels_of(frame);
    const std::string bar_title = frame.landform_classes ? "shape index" : "field";
    int label_width = measure.text_width(bar_title, small) - f - f / 2;
    for (const auto& l : bar.labels)
        label_width = std::max(label_width, measure.text_width(l, small));
    const int bar_w = f;
    const int panel_w = 2 * f + bar_w + f / 2 + label_width + pad;
    const int bar_h = std::clamp(static_cast<int>(std::lround(0.6 * H)), 14 * f, 24 * f);
    const int arrow = 3 * f;
    const int panel_h = 2 * f + bar_h + 2 * f + arrow + 2 * f;
    L.bar_w = bar_w, L.bar_h = bar_h, L.arrow = arrow, L.panel_h = panel_h;

    FramedMap out;
    out.font_size = f;
    out.map_x = pad + left_labels + tick + f / 3;
    out.map_y = pad + f * 3 / 2 + tick;
    const int canvas_w = out.map_x + W + tick + panel_w;
    // Bottom: longitude labels, the scale bar, the caption wrapped to the canvas.
    const std::vector<std::string> lines = caption_lines(frame, measure, canvas_w - 2 * pad, small);
    const int line_h = small * 3 / 2;
    const int bottom = tick + small * 3 / 2 + (frame.metres_per_pixel > 0 ? 3 * f : 0) +
                       static_cast<int>(lines.size()) * line_h + pad;
    const int canvas_h = out.map_y + std::max(H, panel_h) + bottom;
    Canvas c(canvas_w, canvas_h, white, font);

    draw_map(c, image, out, L, canvas_w);
    c.text(pad, pad, frame.title, f, ink, AlignX::left, AlignY::top);

    // The colour bar: 100 at the top, class boundaries and names on its right.
    out.bar_x = out.map_x + W + tick + 2 * f;
    out.bar_y = out.map_y + 2 * f;
    out.bar_w = bar_w;
    out.bar_h = bar_h;
    draw_colour_bar(c, out, L, bar_title, bar, frame.landform_classes);
    if (frame.has_north) draw_north_arrow(c, out, L, frame.north_degrees);

    // The scale bar under the longitude labels, then the caption.
    int y = out.map_y + std::max(H, panel_h) + tick + small * 3 / 2;
    if (frame.metres_per_pixel > 0) y = draw_scale_bar(c, measure, frame, out, L, y);
    for (const auto& line : lines) {
        c.text(pad, y + line_h / 2, line, small, ink, AlignX::left, AlignY::middle);
        y += line_h;
    }
    out.text = c.draws_text();
    out.width = canvas_w;
    out.height = canvas_h;
    out.rgba = std::move(c.rgba());
    return out;
}

}  // namespace terrain::io
