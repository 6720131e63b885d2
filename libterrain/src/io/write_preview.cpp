// preview.png: the map (hillshade, field colours, region boundaries) and its frame (ticks,
// colour bar, scale bar, north arrow, title and caption), drawn on a map_canvas.hpp Canvas.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>

#include "image_module.hpp"
#include "map_canvas.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/describe_dem.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/write_preview.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr int kTarget = 1024;   // long side the small tiles are enlarged to
constexpr int kLargest = 4096;  // long side the large ones are reduced to

// The field's colour: blue (concave, 0) to near-white (flat, 50) to red (convex, 100).
std::array<double, 3> field_colour(double value) {
    static const double stops[5][3] = {
        {30, 60, 200}, {120, 170, 240}, {242, 246, 232}, {245, 160, 120}, {200, 30, 30}};
    const double s = std::clamp(value, 0.0, 100.0) / 25.0;
    const int i = std::min(3, static_cast<int>(s));
    const double t = s - i;
    return {stops[i][0] + t * (stops[i + 1][0] - stops[i][0]),
            stops[i][1] + t * (stops[i + 1][1] - stops[i][1]),
            stops[i][2] + t * (stops[i + 1][2] - stops[i][2])};
}

// Hillshade (Horn's gradient, light from the north-west 45 degrees up), 1 on flat ground; the
// relief is exaggerated when the tile is gentle, so that 90% of slopes stay under 25 degrees
// at most and the shading is visible. NaN where the DEM has NoData. The exaggeration reads
// every pixel's slope (a parallel pass); the shade is then made where it is asked for, at the
// pixels the preview shows (a global grid shows one in 36).
class Hillshade {
  public:
    explicit Hillshade(const Dem& dem) : dem_(dem) {
        const auto d = describe_dem(dem);
        dx_ = d.pixel_width_m > 0 ? d.pixel_width_m : std::abs(dem.transform[1]);
        dy_ = d.pixel_height_m > 0 ? d.pixel_height_m : std::abs(dem.transform[5]);
        // Each pixel's slope (+infinity for NoData, after every valid one in order), and the
        // 90th percentile of the valid ones.
        std::vector<float> slopes(dem.size());
        std::atomic<std::size_t> valid{0};
        tbb::parallel_for(tbb::blocked_range<int>(0, dem.height, 16),
                          [&](const tbb::blocked_range<int>& rows) {
                              std::size_t here = 0;
                              for (int r = rows.begin(); r < rows.end(); ++r)
                                  for (int c = 0; c < dem.width; ++c) {
                                      float& s = slopes[dem.index(c, r)];
                                      if (!dem.valid(c, r)) {
                                          s = std::numeric_limits<float>::infinity();
                                          continue;
                                      }
                                      const auto [gx, gy] = gradient(c, r);
                                      s = std::hypot(gx, gy);
                                      ++here;
                                  }
                              valid += here;
                          });
        if (valid > 0) {
            auto p90 = slopes.begin() + static_cast<std::ptrdiff_t>(valid * 9 / 10);
            std::nth_element(slopes.begin(), p90, slopes.end());
            if (*p90 > 0) exaggeration_ = std::clamp(std::tan(25 * kDegree) / *p90, 1.0, 10.0);
        }
    }

    // The shade of pixel (c, r).
    float at(int c, int r) const {
        if (std::isnan(dem_.values[dem_.index(c, r)])) return std::nanf("");
        const auto [gx, gy] = gradient(c, r);
        const double nx = -gx * exaggeration_, ny = -gy * exaggeration_;
        const double dot =
            (nx * light_[0] + ny * light_[1] + light_[2]) / std::sqrt(nx * nx + ny * ny + 1);
        return static_cast<float>(std::max(0.0, dot) / light_[2]);
    }

  private:
    // Horn's gradient at a valid pixel: east minus west, and north (row - 1) minus south.
    std::array<float, 2> gradient(int c, int r) const {
        const int W = dem_.width, H = dem_.height;
        const double e = dem_.height_at(c, r);
        auto z = [&](int col, int row) {
            col = std::clamp(col, 0, W - 1);
            row = std::clamp(row, 0, H - 1);
            const double v = dem_.at(col, row);
            return std::isnan(v) ? e : dem_.height_at(col, row);
        };
        const double east = z(c + 1, r - 1) + 2 * z(c + 1, r) + z(c + 1, r + 1);
        const double west = z(c - 1, r - 1) + 2 * z(c - 1, r) + z(c - 1, r + 1);
        const double north = z(c - 1, r - 1) + 2 * z(c, r - 1) + z(c + 1, r - 1);
        const double south = z(c - 1, r + 1) + 2 * z(c, r + 1) + z(c + 1, r + 1);
        return {static_cast<float>((east - west) / (8 * dx_)),
                static_cast<float>((north - south) / (8 * dy_))};
    }

    static constexpr double kAltitude = 45 * kDegree, kAzimuth = 315 * kDegree;
    const Dem& dem_;
    double dx_ = 1, dy_ = 1, exaggeration_ = 1;
    // The direction of the light (east, north, up).
    const double light_[3] = {std::cos(kAltitude) * std::sin(kAzimuth),
                              std::cos(kAltitude) * std::cos(kAzimuth), std::sin(kAltitude)};
};

// "12.5", "0.25", "120": `value` with the decimals that `step` needs.
std::string degrees_text(double value, double step) {
    const int decimals = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
    char text[32];
    std::snprintf(text, sizeof text, "%.*f", decimals, value);
    std::string out = text;
    if (out == "-0" || out.find_first_not_of("-0.") == std::string::npos) out = "0";
    return out;
}

std::string tick_label(double value, double step, bool longitude) {
    const double rounded = std::round(value / step) * step;
    if (std::abs(rounded) < step * 1e-6) return "0°";
    const char* hemisphere = longitude ? (rounded > 0 ? "E" : "W") : (rounded > 0 ? "N" : "S");
    return degrees_text(std::abs(rounded), step) + "°" + hemisphere;
}

// A graticule step for `span` degrees: about 3 to 6 lines.
double graticule_step(double span) {
    static const double steps[] = {1, 2, 5, 10, 15, 20, 30, 45, 60, 90};
    if (!(span > 0)) return 1;
    if (span >= 3)
        for (const double s : steps)
            if (span / s <= 6) return s;
    const double magnitude = std::pow(10.0, std::floor(std::log10(span / 6)));
    for (const double m : {1.0, 2.0, 5.0, 10.0})
        if (span / (m * magnitude) <= 6) return m * magnitude;
    return 10 * magnitude;
}

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

std::string metres_text(double metres) {
    char text[32];
    if (metres >= 1000)
        std::snprintf(text, sizeof text, "%.3g km", metres / 1000);
    else
        std::snprintf(text, sizeof text, metres >= 100 ? "%.0f m" : "%.3g m", metres);
    return text;
}

// The frame's plain values: ticks where the frame's edges cross the graticule, the scale and
// north at the centre, title and caption. `scale`: DEM pixels per map pixel.
MapFrame map_frame(const Dem& dem, int width, int height, double scale,
                   const PreviewCaption& caption, int enlarge, int reduce) {
    MapFrame frame;
    const auto& georef = dem.georef;
    // Map pixel (x, y) (corners: integers) -> map coordinates of the DEM's CRS.
    auto map_point = [&](double x, double y) {
        return dem.map_xy(std::min(x * scale, double(dem.width)),
                          std::min(y * scale, double(dem.height)));
    };
    const auto* lonlat = georef.output_lonlat.get();
    double centre_lat = 0;
    bool centre_known = false;
    if (lonlat) {
        // Longitude along the top (0) and bottom (2) edges, latitude along the left (3) and
        // right (1) ones, at every map pixel's corner.
        struct Edge {
            int edge;
            bool longitude;
            std::vector<double> values;
            std::vector<std::uint8_t> ok;
        };
        std::vector<Edge> edges;
        for (const int e : {0, 2, 3, 1}) {
            const bool horizontal = e == 0 || e == 2;
            const int n = (horizontal ? width : height) + 1;
            std::vector<double> xs(static_cast<std::size_t>(n)), ys(static_cast<std::size_t>(n));
            std::vector<std::uint8_t> ok(std::size_t(n), 0);
            for (int i = 0; i < n; ++i) {
                const auto p = horizontal ? map_point(i, e == 0 ? 0 : height)
                                          : map_point(e == 3 ? 0 : width, i);
                xs[std::size_t(i)] = p[0];
                ys[std::size_t(i)] = p[1];
            }
            lonlat->to_lonlat(xs.size(), xs.data(), ys.data(), ok.data());
            edges.push_back({e, horizontal, horizontal ? xs : ys, ok});
        }
        for (const bool longitude : {true, false}) {
            double lo = 1e300, hi = -1e300;
            for (const auto& edge : edges)
                if (edge.longitude == longitude)
                    for (std::size_t i = 0; i < edge.values.size(); ++i)
                        if (edge.ok[i]) {
                            lo = std::min(lo, edge.values[i]);
                            hi = std::max(hi, edge.values[i]);
                        }
            if (!(hi > lo)) continue;
            const double step = graticule_step(hi - lo);
            for (const auto& edge : edges) {
                if (edge.longitude != longitude) continue;
                const double length = static_cast<double>(edge.values.size() - 1);
                for (std::size_t i = 0; i + 1 < edge.values.size(); ++i) {
                    if (!edge.ok[i] || !edge.ok[i + 1]) continue;
                    const double a = edge.values[i], b = edge.values[i + 1];
                    if (a == b || std::abs(b - a) > 180) continue;  // the seam
                    for (double k = std::ceil(std::min(a, b) / step); k * step <= std::max(a, b);
                         ++k) {
                        const double v = k * step;
                        // Each crossing once: at the sample it reaches, not the one it leaves.
                        const double t = (v - a) / (b - a);
                        if (t <= 0 && i > 0) continue;
                        const double position = double(i) + t;
                        if (position < 2 || position > length - 2) continue;
                        frame.ticks.push_back(
                            {edge.edge, position, tick_label(v, step, longitude)});
                    }
                }
            }
        }
        // North: the direction in which latitude grows at the centre.
        const double cx = width / 2.0, cy = height / 2.0;
        const double d = std::max(1.0, 0.01 * std::min(width, height));
        std::array<double, 5> xs{}, ys{};
        const std::array<std::array<double, 2>, 5> at{
            {{cx, cy}, {cx + d, cy}, {cx - d, cy}, {cx, cy + d}, {cx, cy - d}}};
        for (std::size_t k = 0; k < 5; ++k) {
            const auto p = map_point(at[k][0], at[k][1]);
            xs[k] = p[0];
            ys[k] = p[1];
        }
        std::array<std::uint8_t, 5> ok{};
        if (lonlat->to_lonlat(5, xs.data(), ys.data(), ok.data())) {
            centre_lat = ys[0];
            centre_known = true;
            const double gx = (ys[1] - ys[2]) / (2 * d), gy = (ys[3] - ys[4]) / (2 * d);
            if (std::hypot(gx, gy) > 1e-12 && std::abs(ys[0]) < 89.9) {
                frame.has_north = true;
                frame.north_degrees = std::atan2(gx, -gy) / kDegree;
            }
        }
    }
    double pixel_m = georef.pixel_width_m;
    if (!(pixel_m > 0)) pixel_m = std::abs(dem.transform[1]);
    frame.metres_per_pixel = pixel_m * scale;
    if (georef.kind == CrsKind::geographic && centre_known)
        frame.scale_note = "east-west scale true along " + tick_label(centre_lat, 0.1, false) +
                           " (the map's centre); it varies with latitude";
    else if (centre_known)
        frame.scale_note = "east-west scale true at the map's centre (" +
                           tick_label(centre_lat, 0.1, false) + "); it varies across the map";
    else if (georef.kind == CrsKind::none)
        frame.scale_note = "local grid without CRS: map units taken as metres";
    else
        frame.scale_note = "east-west scale true at the map's centre";

    const std::string input = !caption.input.empty()
                                  ? caption.input
                                  : std::filesystem::path(dem.source).filename().string();
    const bool local = !dem.body.has_crs;
    frame.title = (local ? std::string("local grid") : dem.body.name) +
                  (input.empty() ? std::string() : " · " + input);
    frame.landform_classes = caption.field == "shape-index";
    frame.caption.push_back(frame.landform_classes ? "field: shape index ×100"
                                                   : "field: " + caption.field);
    for (const auto& p : caption.parameters) frame.caption.push_back(p);
    if (caption.regions > 0) frame.caption.push_back(std::to_string(caption.regions) + " regions");
    frame.caption.push_back(
        local ? std::string("no CRS")
              : "CRS: " + (georef.crs_name.empty() ? std::string("unnamed") : georef.crs_name));
    frame.caption.push_back(std::to_string(dem.width) + " × " + std::to_string(dem.height) +
                            " pixels of " + metres_text(pixel_m));
    if (enlarge > 1)
        frame.caption.push_back("shown ×" + std::to_string(enlarge));
    else if (reduce > 1)
        frame.caption.push_back("shown at 1/" + std::to_string(reduce));
    if (!lonlat && !local) frame.caption.push_back("no longitude/latitude for this CRS");
    if (lonlat && !frame.has_north) frame.caption.push_back("north: undefined at the centre");
    for (auto& item : frame.caption) {  // names may end in spaces ("EQUIRECTANGULAR VESTA ")
        const auto first = item.find_first_not_of(' '), last = item.find_last_not_of(' ');
        item = first == std::string::npos ? std::string() : item.substr(first, last - first + 1);
    }
    std::erase(frame.caption, std::string());
    return frame;
}

}  // namespace

std::array<std::uint8_t, 3> preview_field_colour(double value) {
    const auto c = field_colour(value);
    return {static_cast<std::uint8_t>(std::lround(c[0])),
            static_cast<std::uint8_t>(std::lround(c[1])),
            static_cast<std::uint8_t>(std::lround(c[2]))};
}

PreviewImage render_preview(const Dem& dem, const std::vector<float>& field_pixels,
                            const std::vector<std::uint32_t>& pixels,
                            const PreviewCaption& caption) {
    if (pixels.size() != dem.size() || field_pixels.size() != dem.size())
        throw Error("write", "the preview needs one label and one field value per DEM pixel");
    const int W = dem.width, H = dem.height, longest = std::max(W, H);
    // Output pixel X shows source column X * reduce / enlarge.
    const int enlarge = std::max(1, (kTarget + longest / 2) / longest);
    const int reduce = longest > kLargest ? (longest + kLargest - 1) / kLargest : 1;
    const int OW = (W * enlarge + reduce - 1) / reduce, OH = (H * enlarge + reduce - 1) / reduce;
    std::vector<int> src_col(static_cast<std::size_t>(OW)), src_row(static_cast<std::size_t>(OH));
    for (int x = 0; x < OW; ++x) src_col[std::size_t(x)] = std::min(W - 1, x * reduce / enlarge);
    for (int y = 0; y < OH; ++y) src_row[std::size_t(y)] = std::min(H - 1, y * reduce / enlarge);

    const Hillshade shade(dem);
    // A source pixel's colour (transparent for NoData or no region).
    const auto colour = [&](int c, int r) -> std::array<std::uint8_t, 4> {
        const auto i = dem.index(c, r);
        if (pixels[i] == 0 || std::isnan(field_pixels[i])) return {0, 0, 0, 0};
        const float s = shade.at(c, r);
        if (std::isnan(s)) return {0, 0, 0, 0};
        const auto f = field_colour(field_pixels[i]);
        const double light = 0.3 + 0.7 * std::min(1.3, static_cast<double>(s));
        std::array<std::uint8_t, 4> rgba{0, 0, 0, 255};
        for (int k = 0; k < 3; ++k)
            rgba[std::size_t(k)] = static_cast<std::uint8_t>(
                std::lround(std::clamp(f[std::size_t(k)] * light, 0.0, 255.0)));
        return rgba;
    };
    std::vector<std::uint8_t> image(static_cast<std::size_t>(OW) * OH * 4);
    auto label_at = [&](int x, int y) {
        return pixels[dem.index(src_col[std::size_t(x)], src_row[std::size_t(y)])];
    };
    tbb::parallel_for(tbb::blocked_range<int>(0, OH, 8), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < OW; ++x) {
                const int c = src_col[std::size_t(x)], r = src_row[std::size_t(y)];
                auto rgba = colour(c, r);
                // Region boundaries: a labelled pixel whose right or lower neighbour (in the
                // output) is in another region; 1 output pixel wide.
                const auto l = pixels[dem.index(c, r)];
                if (l != 0 && rgba[3] != 0) {
                    const auto right = x + 1 < OW ? label_at(x + 1, y) : l;
                    const auto below = y + 1 < OH ? label_at(x, y + 1) : l;
                    if ((right != 0 && right != l) || (below != 0 && below != l))
                        rgba = {0, 0, 0, 255};
                }
                std::copy(
                    rgba.begin(), rgba.end(),
                    image.begin() + static_cast<std::ptrdiff_t>((std::size_t(y) * OW + x) * 4));
            }
    });

    return {OW, OH, std::move(image),
            map_frame(dem, OW, OH, double(reduce) / enlarge, caption, enlarge, reduce)};
}

FramedMap frame_preview(const PreviewImage& image) {
    using detail::AlignX;
    using detail::AlignY;
    using detail::Canvas;
    using detail::Rgba;
    const MapFrame& frame = image.frame;
    const int W = image.width, H = image.height;
    const int f = std::clamp(static_cast<int>(std::lround(std::max(W, H) / 64.0)), 13, 28);
    const int small = std::max(11, f * 7 / 8);
    const int pad = f, tick = std::max(4, f / 2);
    const std::string font = detail::map_font();
    Canvas measure(1, 1, {255, 255, 255, 255}, font);
    const Rgba ink{25, 25, 25, 255}, white{255, 255, 255, 255};

    // Left: the latitudes' labels; bottom edge: the longitudes'.
    int left_labels = 0;
    for (const auto& t : frame.ticks)
        if (t.edge == 3) left_labels = std::max(left_labels, measure.text_width(t.label, small));
    // Right panel: the colour bar, its labels and title, the north arrow.
    std::vector<std::string> bar_labels;
    std::vector<double> bar_values;
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
    const std::string bar_title = frame.landform_classes ? "shape index" : "field";
    int label_width = measure.text_width(bar_title, small) - f - f / 2;
    for (const auto& l : bar_labels)
        label_width = std::max(label_width, measure.text_width(l, small));
    const int bar_w = f;
    const int panel_w = 2 * f + bar_w + f / 2 + label_width + pad;
    const int bar_h = std::clamp(static_cast<int>(std::lround(0.6 * H)), 14 * f, 24 * f);
    const int arrow = 3 * f;
    const int panel_h = 2 * f + bar_h + 2 * f + arrow + 2 * f;

    FramedMap out;
    out.font_size = f;
    out.map_x = pad + left_labels + tick + f / 3;
    out.map_y = pad + f * 3 / 2 + tick;
    const int canvas_w = out.map_x + W + tick + panel_w;
    // Bottom: longitude labels, the scale bar, the caption wrapped to the canvas.
    std::vector<std::string> lines;
    {
        const int room = canvas_w - 2 * pad;
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
    }
    const int line_h = small * 3 / 2;
    const int bottom = tick + small * 3 / 2 + (frame.metres_per_pixel > 0 ? 3 * f : 0) +
                       static_cast<int>(lines.size()) * line_h + pad;
    const int canvas_h = out.map_y + std::max(H, panel_h) + bottom;
    Canvas c(canvas_w, canvas_h, white, font);

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
    c.text(pad, pad, frame.title, f, ink, AlignX::left, AlignY::top);

    // The colour bar: 100 at the top, class boundaries and names on its right.
    out.bar_x = out.map_x + W + tick + 2 * f;
    out.bar_y = out.map_y + 2 * f;
    out.bar_w = bar_w;
    out.bar_h = bar_h;
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
    if (frame.landform_classes)
        for (int k = 1; k < 9; ++k)  // class boundaries: 6.25, 18.75, ..., 93.75
            c.fill(out.bar_x + bar_w, bar_row(6.25 + 12.5 * (k - 1)), f / 3, 1, ink);
    for (std::size_t k = 0; k < bar_labels.size(); ++k) {
        const int row = bar_row(bar_values[k]);
        if (!frame.landform_classes) c.fill(out.bar_x + bar_w, row, f / 3, 1, ink);
        c.text(out.bar_x + bar_w + f / 2, row, bar_labels[k], small, ink, AlignX::left,
               AlignY::middle);
    }

    // The north arrow below the bar.
    if (frame.has_north) {
        const double cx = out.bar_x + bar_w / 2.0, cy = out.bar_y + bar_h + 3 * f + arrow / 2.0;
        const double a = frame.north_degrees * kDegree;
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

    // The scale bar under the longitude labels: four segments, black and white.
    int y = out.map_y + std::max(H, panel_h) + tick + small * 3 / 2;
    if (frame.metres_per_pixel > 0) {
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
        c.text(x0 + length, bar_y + h + small / 4, length_text(length_m), small, ink,
               AlignX::centre, AlignY::top);
        const int after = x0 + length + measure.text_width(length_text(length_m), small) / 2 + f;
        c.text(after, bar_y + h / 2, frame.scale_note, small, ink, AlignX::left, AlignY::middle);
        y += 3 * f;
    }
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

void write_preview_image(const PreviewImage& image, const std::string& path, bool overwrite) {
    if (image.rgba.size() != static_cast<std::size_t>(image.width) * image.height * 4)
        throw Error("write", "the preview image's size does not match its pixels");
    const auto framed = frame_preview(image);
    AtomicOutput output(path, overwrite);
    // zlib level 1: faster than the default level 6, for a slightly larger file.
    detail::write_image(output.temp_path(), path, framed.width, framed.height, 4,
                        framed.rgba.data(), 1);
    output.commit();
}

void write_preview_png(const Dem& dem, const std::vector<float>& field_pixels,
                       const std::vector<std::uint32_t>& pixels, const std::string& path,
                       bool overwrite, const PreviewCaption& caption) {
    check_output_path(path, overwrite);
    write_preview_image(render_preview(dem, field_pixels, pixels, caption), path, overwrite);
}

}  // namespace terrain::io
