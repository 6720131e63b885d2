// preview.png: the map (hillshade, field colours, region boundaries) and its frame's values
// (ticks, scale, north, title and caption); the frame is drawn by preview_frame.cpp.

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
#include <optional>
#include <string>

#include "image_files.hpp"
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

std::string metres_text(double metres) {
    char text[32];
    if (metres >= 1000)
        std::snprintf(text, sizeof text, "%.3g km", metres / 1000);
    else
        std::snprintf(text, sizeof text, metres >= 100 ? "%.0f m" : "%.3g m", metres);
    return text;
}

// Map pixel (x, y) of the preview (corners: integers) -> map coordinates of the DEM's CRS;
// `scale`: DEM pixels per map pixel.
struct MapPoints {
    const Dem& dem;
    double scale;
    std::array<double, 2> operator()(double x, double y) const {
        return dem.map_xy(std::min(x * scale, double(dem.width)),
                          std::min(y * scale, double(dem.height)));
    }
};

// The ticks where the frame's edges cross the graticule.
void graticule_ticks(MapFrame& frame, const MapPoints& map_point, const LonLatMapping& lonlat,
                     int width, int height) {
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
            const auto p =
                horizontal ? map_point(i, e == 0 ? 0 : height) : map_point(e == 3 ? 0 : width, i);
            xs[std::size_t(i)] = p[0];
            ys[std::size_t(i)] = p[1];
        }
        lonlat.to_lonlat(xs.size(), xs.data(), ys.data(), ok.data());
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
                for (double k = std::ceil(std::min(a, b) / step); k * step <= std::max(a, b); ++k) {
                    const double v = k * step;
                    // Each crossing once: at the sample it reaches, not the one it leaves.
                    const double t = (v - a) / (b - a);
                    if (t <= 0 && i > 0) continue;
                    const double position = double(i) + t;
                    if (position < 2 || position > length - 2) continue;
                    frame.ticks.push_back({edge.edge, position, tick_label(v, step, longitude)});
                }
            }
        }
    }
}

// North at the centre of the frame (the direction in which latitude grows there); the
// latitude of the centre when it is known.
std::optional<double> north_at_centre(MapFrame& frame, const MapPoints& map_point,
                                      const LonLatMapping& lonlat, int width, int height) {
    std::optional<double> centre_lat;
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
    if (lonlat.to_lonlat(5, xs.data(), ys.data(), ok.data())) {
        centre_lat = ys[0];
        const double gx = (ys[1] - ys[2]) / (2 * d), gy = (ys[3] - ys[4]) / (2 * d);
        if (std::hypot(gx, gy) > 1e-12 && std::abs(ys[0]) < 89.9) {
            frame.has_north = true;
            frame.north_degrees = std::atan2(gx, -gy) / kDegree;
        }
    }
    return centre_lat;
}

// The frame's title and caption: the body and input, the field and its parameters, the CRS,
// the grid, the scale shown.
void frame_caption(MapFrame& frame, const Dem& dem, const PreviewCaption& caption, double pixel_m,
                   int enlarge, int reduce, bool has_lonlat) {
    const auto& georef = dem.georef;
    const std::string input = !caption.input.empty()
                                  ? caption.input
                                  : std::filesystem::path(dem.source).filename().string();
    const bool local = !dem.body.has_crs;
    frame.title = (local ? std::string("local grid") : dem.body.name) +
                  (input.empty() ? std::string() : " · " + input);
    frame.landform_classes = caption.field == field::FieldKind::shape_index;
    frame.caption.push_back(frame.landform_classes
                                ? "field: shape index ×100"
                                : std::string("field: ") + field::to_string(caption.field));
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
    if (!has_lonlat && !local) frame.caption.push_back("no longitude/latitude for this CRS");
    if (has_lonlat && !frame.has_north) frame.caption.push_back("north: undefined at the centre");
    for (auto& item : frame.caption) {  // names may end in spaces ("EQUIRECTANGULAR VESTA ")
        const auto first = item.find_first_not_of(' '), last = item.find_last_not_of(' ');
        item = first == std::string::npos ? std::string() : item.substr(first, last - first + 1);
    }
    std::erase(frame.caption, std::string());
}

// The frame's plain values: ticks where the frame's edges cross the graticule, the scale and
// north at the centre, title and caption. `scale`: DEM pixels per map pixel.
MapFrame map_frame(const Dem& dem, int width, int height, double scale,
                   const PreviewCaption& caption, int enlarge, int reduce) {
    MapFrame frame;
    const auto& georef = dem.georef;
    const MapPoints map_point{dem, scale};
    const auto* lonlat = georef.output_lonlat.get();
    double centre_lat = 0;
    bool centre_known = false;
    if (lonlat) {
        graticule_ticks(frame, map_point, *lonlat, width, height);
        if (const auto lat = north_at_centre(frame, map_point, *lonlat, width, height)) {
            centre_lat = *lat;
            centre_known = true;
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

    frame_caption(frame, dem, caption, pixel_m, enlarge, reduce, lonlat != nullptr);
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
    // An enlarged tile shows each source pixel enlarge^2 times: its colours are made once.
    std::vector<std::array<std::uint8_t, 4>> colours;
    if (enlarge > 1) {
        colours.resize(dem.size());
        tbb::parallel_for(tbb::blocked_range<int>(0, H, 8),
                          [&](const tbb::blocked_range<int>& rows) {
                              for (int r = rows.begin(); r < rows.end(); ++r)
                                  for (int c = 0; c < W; ++c)
                                      colours[dem.index(c, r)] = colour(c, r);
                          });
    }
    const auto colour_at = [&](int c, int r) {
        return colours.empty() ? colour(c, r) : colours[dem.index(c, r)];
    };
    std::vector<std::uint8_t> image(static_cast<std::size_t>(OW) * OH * 4);
    auto label_at = [&](int x, int y) {
        return pixels[dem.index(src_col[std::size_t(x)], src_row[std::size_t(y)])];
    };
    tbb::parallel_for(tbb::blocked_range<int>(0, OH, 8), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < OW; ++x) {
                const int c = src_col[std::size_t(x)], r = src_row[std::size_t(y)];
                auto rgba = colour_at(c, r);
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
