
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "image_module.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/describe_dem.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/write_preview.hpp"

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
// at most and the shading is visible. NaN where the DEM has NoData.
std::vector<float> hillshade(const Dem& dem) {
    const auto d = describe_dem(dem);
    const double dx = d.pixel_width_m > 0 ? d.pixel_width_m : std::abs(dem.transform[1]);
    const double dy = d.pixel_height_m > 0 ? d.pixel_height_m : std::abs(dem.transform[5]);
    const int W = dem.width, H = dem.height;
    auto z = [&](int col, int row, double centre) {
        col = std::clamp(col, 0, W - 1);
        row = std::clamp(row, 0, H - 1);
        const double v = dem.at(col, row);
        return std::isnan(v) ? centre : dem.height_at(col, row);
    };
    std::vector<float> gx(dem.size(), 0.f), gy(dem.size(), 0.f);
    std::vector<float> slopes;
    slopes.reserve(dem.size());
    for (int r = 0; r < H; ++r)
        for (int c = 0; c < W; ++c) {
            if (!dem.valid(c, r)) continue;
            const double e = dem.height_at(c, r);
            // East minus west, and north (row - 1) minus south.
            const double east = z(c + 1, r - 1, e) + 2 * z(c + 1, r, e) + z(c + 1, r + 1, e);
            const double west = z(c - 1, r - 1, e) + 2 * z(c - 1, r, e) + z(c - 1, r + 1, e);
            const double north = z(c - 1, r - 1, e) + 2 * z(c, r - 1, e) + z(c + 1, r - 1, e);
            const double south = z(c - 1, r + 1, e) + 2 * z(c, r + 1, e) + z(c + 1, r + 1, e);
            const auto i = dem.index(c, r);
            gx[i] = static_cast<float>((east - west) / (8 * dx));
            gy[i] = static_cast<float>((north - south) / (8 * dy));
            slopes.push_back(std::hypot(gx[i], gy[i]));
        }
    double exaggeration = 1;
    if (!slopes.empty()) {
        auto p90 = slopes.begin() + static_cast<std::ptrdiff_t>(slopes.size() * 9 / 10);
        std::nth_element(slopes.begin(), p90, slopes.end());
        if (*p90 > 0) exaggeration = std::clamp(std::tan(25 * kDegree) / *p90, 1.0, 10.0);
    }
    const double altitude = 45 * kDegree, azimuth = 315 * kDegree;
    const double light[3] = {std::cos(altitude) * std::sin(azimuth),
                             std::cos(altitude) * std::cos(azimuth), std::sin(altitude)};
    std::vector<float> shade(dem.size(), std::nanf(""));
    for (std::size_t i = 0; i < dem.size(); ++i) {
        if (std::isnan(dem.values[i])) continue;
        const double nx = -gx[i] * exaggeration, ny = -gy[i] * exaggeration;
        const double dot =
            (nx * light[0] + ny * light[1] + light[2]) / std::sqrt(nx * nx + ny * ny + 1);
        shade[i] = static_cast<float>(std::max(0.0, dot) / light[2]);
    }
    return shade;
}

}  // namespace

PreviewImage render_preview(const Dem& dem, const std::vector<float>& field_pixels,
                            const std::vector<std::uint32_t>& pixels) {
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

    const auto shade = hillshade(dem);
    // Colour per source pixel once; the output picks.
    std::vector<std::array<std::uint8_t, 4>> colour(dem.size(), {0, 0, 0, 0});
    for (std::size_t i = 0; i < dem.size(); ++i) {
        if (pixels[i] == 0 || std::isnan(shade[i]) || std::isnan(field_pixels[i])) continue;
        const auto c = field_colour(field_pixels[i]);
        const double light = 0.3 + 0.7 * std::min(1.3, static_cast<double>(shade[i]));
        for (int k = 0; k < 3; ++k)
            colour[i][std::size_t(k)] = static_cast<std::uint8_t>(
                std::lround(std::clamp(c[std::size_t(k)] * light, 0.0, 255.0)));
        colour[i][3] = 255;
    }
    std::vector<std::uint8_t> image(static_cast<std::size_t>(OW) * OH * 4);
    auto label_at = [&](int x, int y) {
        return pixels[dem.index(src_col[std::size_t(x)], src_row[std::size_t(y)])];
    };
    for (int y = 0; y < OH; ++y)
        for (int x = 0; x < OW; ++x) {
            const auto i = dem.index(src_col[std::size_t(x)], src_row[std::size_t(y)]);
            auto rgba = colour[i];
            // Region boundaries: a labelled pixel whose right or lower neighbour (in the
            // output) is in another region; 1 output pixel wide.
            const auto l = pixels[i];
            if (l != 0 && rgba[3] != 0) {
                const auto right = x + 1 < OW ? label_at(x + 1, y) : l;
                const auto below = y + 1 < OH ? label_at(x, y + 1) : l;
                if ((right != 0 && right != l) || (below != 0 && below != l)) rgba = {0, 0, 0, 255};
            }
            std::copy(rgba.begin(), rgba.end(),
                      image.begin() + static_cast<std::ptrdiff_t>((std::size_t(y) * OW + x) * 4));
        }

    return {OW, OH, std::move(image)};
}

void write_preview_image(const PreviewImage& image, const std::string& path, bool overwrite) {
    if (image.rgba.size() != static_cast<std::size_t>(image.width) * image.height * 4)
        throw Error("write", "the preview image's size does not match its pixels");
    AtomicOutput output(path, overwrite);
    // zlib level 1: a third faster than 6, 3% larger.
    detail::write_image(output.temp_path(), path, image.width, image.height, 4, image.rgba.data(),
                        1);
    output.commit();
}

void write_preview_png(const Dem& dem, const std::vector<float>& field_pixels,
                       const std::vector<std::uint32_t>& pixels, const std::string& path,
                       bool overwrite) {
    check_output_path(path, overwrite);
    write_preview_image(render_preview(dem, field_pixels, pixels), path, overwrite);
}

}  // namespace terrain::io
