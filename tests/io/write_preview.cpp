#include <gdal_priv.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "support/segment_support.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/io/write_preview.hpp"
#include "terrain/io/write_sweep_plot.hpp"

using namespace terrain;

namespace {

struct Png {
    int width = 0, height = 0, channels = 0;
    std::vector<std::uint8_t> pixels;
    std::array<int, 4> at(int x, int y) const {
        const auto i = (std::size_t(y) * width + x) * channels;
        return {pixels[i], pixels[i + 1], pixels[i + 2], channels == 4 ? pixels[i + 3] : 255};
    }
};

Png read_png(const std::string& path) {
    GDALDatasetUniquePtr in(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
    REQUIRE(in);
    Png png;
    png.width = in->GetRasterXSize();
    png.height = in->GetRasterYSize();
    png.channels = in->GetRasterCount();
    png.pixels.resize(std::size_t(png.width) * png.height * png.channels);
    // Pixel-interleaved, as the file stores them.
    REQUIRE(in->RasterIO(GF_Read, 0, 0, png.width, png.height, png.pixels.data(), png.width,
                         png.height, GDT_Byte, png.channels, nullptr, png.channels,
                         GSpacing(png.width) * png.channels, 1, nullptr) == CE_None);
    return png;
}

// Dark pixels (text, lines) in a rectangle of the image.
int dark_pixels(const Png& png, int x0, int y0, int x1, int y1) {
    int n = 0;
    for (int y = std::max(0, y0); y < std::min(png.height, y1); ++y)
        for (int x = std::max(0, x0); x < std::min(png.width, x1); ++x) {
            const auto p = png.at(x, y);
            if (p[3] == 255 && p[0] + p[1] + p[2] < 300) ++n;
        }
    return n;
}

// Sets an environment variable for one scope.
class ScopedEnv {
  public:
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        setenv(name, value, 1);
    }
    ~ScopedEnv() {
        if (old_.empty())
            unsetenv(name_);
        else
            setenv(name_, old_.c_str(), 1);
    }

  private:
    const char* name_;
    std::string old_;
};

test::SegmentedTile vesta_tile() {
    Dem vesta = test::crop(io::read_dem(test::sample("vesta_hamo_tile.lbl")), 0, 0, 64, 48);
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 8; ++c) vesta.values[vesta.index(c, r)] = std::nan("");
    return test::segment_tile(vesta, test::voronoi_cells(vesta, 3, 2));
}

}  // namespace

TEST_CASE(
    "preview.png: the map enlarged to about 1024 pixels, boundaries black, NoData "
    "transparent, inside its frame",
    "[write_preview]") {
    const auto t = vesta_tile();
    const auto dir = test::scratch_dir("write_preview");
    const auto path = (dir / "preview.png").string();
    const auto field = field::field_to_pixels(t.mesh, t.dem, t.field);
    io::write_preview_png(t.dem, field, t.pixels, path, false);

    const auto image = io::render_preview(t.dem, field, t.pixels);
    const int k = 16;  // 1024 / 64
    CHECK(image.width == 64 * k);
    CHECK(image.height == 48 * k);
    const auto framed = io::frame_preview(image);
    const auto png = read_png(path);
    CHECK(png.width == framed.width);
    CHECK(png.height == framed.height);
    CHECK(png.channels == 4);
    // A margin on every side: title and ticks above and left, the colour bar right, the
    // scale bar and caption below.
    CHECK(framed.map_x > 2 * framed.font_size);
    CHECK(framed.map_y > framed.font_size);
    CHECK(framed.width - framed.map_x - image.width > 5 * framed.font_size);
    CHECK(framed.height - framed.map_y - image.height > 3 * framed.font_size);
    CHECK(framed.bar_x > framed.map_x + image.width);
    const int X = framed.map_x, Y = framed.map_y;
    auto pixel = [&](int x, int y) { return png.at(X + x, Y + y); };
    // The margin is opaque white where nothing is drawn; NoData (top-left block) is
    // transparent, labelled pixels are opaque.
    CHECK(png.at(2, png.height - 2) == std::array<int, 4>{255, 255, 255, 255});
    CHECK(pixel(3 * k, 2 * k)[3] == 0);
    CHECK(pixel(40 * k + 3, 30 * k + 3)[3] == 255);
    // The frame: a black line one pixel outside the map.
    CHECK(png.at(X - 1, Y + 30 * k) == std::array<int, 4>{25, 25, 25, 255});
    CHECK(png.at(X + image.width, Y + 30 * k) == std::array<int, 4>{25, 25, 25, 255});
    // Where two regions meet along a row, the last output column of the left pixel is black.
    bool found = false;
    for (int r = 10; r < 48 && !found; ++r)
        for (int c = 10; c + 1 < 64 && !found; ++c) {
            const auto a = t.pixels[t.dem.index(c, r)], b = t.pixels[t.dem.index(c + 1, r)];
            if (a == 0 || b == 0 || a == b) continue;
            found = true;
            CHECK(pixel(c * k + k - 1, r * k + k / 2) == std::array<int, 4>{0, 0, 0, 255});
            CHECK(pixel(c * k + k / 2, r * k + k / 2) != std::array<int, 4>{0, 0, 0, 255});
        }
    CHECK(found);
    // Colours follow the field: a cup-like pixel is bluer than red, a cap-like one redder.
    for (std::size_t p = 0; p < t.dem.size(); p += 7) {
        if (t.pixels[p] == 0) continue;
        const int x = int(p % 64) * k + k / 2, y = int(p / 64) * k + k / 2;
        const auto c = pixel(x, y);
        if (c == std::array<int, 4>{0, 0, 0, 255}) continue;
        if (field[p] < 15) CHECK(c[2] > c[0]);
        if (field[p] > 85) CHECK(c[0] > c[2]);
    }

    const auto first = test::file_bytes(path);
    CHECK_THROWS_AS(io::write_preview_png(t.dem, field, t.pixels, path, false), Error);
    io::write_preview_png(t.dem, field, t.pixels, path, true);
    CHECK(test::file_bytes(path) == first);
}

TEST_CASE("preview.png: the colour bar shows the landform classes' colours in order",
          "[write_preview]") {
    const auto t = vesta_tile();
    const auto field = field::field_to_pixels(t.mesh, t.dem, t.field);
    const auto framed = io::frame_preview(io::render_preview(t.dem, field, t.pixels));
    REQUIRE(framed.bar_h > 100);
    auto bar = [&](double value) {
        const int y =
            framed.bar_y + std::min(framed.bar_h - 1, int((1 - value / 100) * framed.bar_h));
        const auto i = (std::size_t(y) * framed.width + framed.bar_x + framed.bar_w / 2) * 4;
        return std::array<int, 3>{framed.rgba[i], framed.rgba[i + 1], framed.rgba[i + 2]};
    };
    // The nine classes' centres, cup (bottom) to cap (top): the map's colours for them.
    const double centres[] = {3.125, 12.5, 25, 37.5, 50, 62.5, 75, 87.5, 96.875};
    std::array<int, 3> previous{};
    for (int k = 0; k < 9; ++k) {
        const auto c = bar(centres[k]);
        const auto expected = io::preview_field_colour(centres[k]);
        for (int j = 0; j < 3; ++j)
            CHECK(std::abs(c[std::size_t(j)] - int(expected[std::size_t(j)])) <= 2);
        if (k > 0) CHECK(c[0] - c[2] > previous[0] - previous[2]);  // redder upwards
        previous = c;
    }
    CHECK(bar(3.125)[2] > bar(3.125)[0]);    // cup: blue
    CHECK(bar(96.875)[0] > bar(96.875)[2]);  // cap: red
}

TEST_CASE(
    "preview.png: ticks, scale and north from the DEM's CRS, text where a font is found, "
    "none and no failure without one",
    "[write_preview]") {
    const auto t = vesta_tile();
    const auto field = field::field_to_pixels(t.mesh, t.dem, t.field);
    io::PreviewCaption caption;
    caption.input = "vesta_hamo_tile.lbl";
    caption.parameters = {"persistence 10", "area ratio 0.5 %"};
    caption.regions = 6;
    const auto image = io::render_preview(t.dem, field, t.pixels, caption);
    const auto& frame = image.frame;
    // An equirectangular grid: north is up, and the scale is the pixel size over 16.
    REQUIRE(frame.has_north);
    CHECK(std::abs(frame.north_degrees) < 0.01);
    CHECK(frame.metres_per_pixel == Approx(t.dem.georef.pixel_width_m / 16).epsilon(1e-9));
    CHECK(frame.scale_note.find("S)") != std::string::npos);  // true at the centre's latitude
    CHECK(frame.title == "Vesta · vesta_hamo_tile.lbl");
    CHECK(std::find(frame.caption.begin(), frame.caption.end(), "6 regions") !=
          frame.caption.end());
    CHECK(std::find(frame.caption.begin(), frame.caption.end(), "area ratio 0.5 %") !=
          frame.caption.end());
    // Longitudes east on the top and bottom edges, latitudes south on the left and right,
    // each increasing in its direction (east to the right, north upwards).
    int by_edge[4] = {0, 0, 0, 0};
    for (const auto& tick : frame.ticks) {
        ++by_edge[tick.edge];
        const char hemisphere = tick.label.back();
        CHECK(hemisphere == (tick.edge % 2 == 0 ? 'E' : 'S'));
        CHECK(tick.label.find("°") != std::string::npos);
        CHECK(tick.position > 0);
        CHECK(tick.position < (tick.edge % 2 == 0 ? image.width : image.height));
    }
    CHECK(by_edge[0] > 0);
    CHECK(by_edge[0] == by_edge[2]);
    CHECK(by_edge[3] > 0);
    CHECK(by_edge[1] == by_edge[3]);

    const auto framed = io::frame_preview(image);
    const auto dir = test::scratch_dir("write_preview_text");
    // With the font (installed by the set-up: fonts-dejavu-core): text in the title's place
    // and beside the colour bar.
    REQUIRE(io::map_text_warning().empty());
    CHECK(framed.text);
    io::write_preview_image(image, (dir / "with_font.png").string(), false);
    const auto with_font = read_png((dir / "with_font.png").string());
    const int f = framed.font_size;
    CHECK(dark_pixels(with_font, 0, 0, framed.width, framed.map_y - f) > 40);
    CHECK(dark_pixels(with_font, framed.bar_x + framed.bar_w + f / 2, framed.bar_y, framed.width,
                      framed.bar_y + framed.bar_h) > 100);
    // Without one: the same frame with no text, a warning to give, no exception.
    {
        const ScopedEnv no_font("TERRAIN_FONT", (dir / "missing.ttf").c_str());
        CHECK_FALSE(io::map_text_warning().empty());
        const auto bare = io::frame_preview(image);
        CHECK_FALSE(bare.text);
        CHECK(bare.map_x > 0);
        io::write_preview_image(image, (dir / "without_font.png").string(), false);
        const auto without = read_png((dir / "without_font.png").string());
        CHECK(dark_pixels(without, 0, 0, without.width, bare.map_y - f) == 0);
        CHECK(dark_pixels(without, bare.bar_x + bare.bar_w + f / 2, bare.bar_y, without.width,
                          bare.bar_y + bare.bar_h) == 0);
    }
}

TEST_CASE("preview.png: a wide grid is reduced to at most 4096 pixels", "[write_preview]") {
    Dem dem;
    dem.width = 9001;
    dem.height = 13;
    dem.values.resize(std::size_t(dem.width) * dem.height);
    for (int r = 0; r < dem.height; ++r)
        for (int c = 0; c < dem.width; ++c)
            dem.values[dem.index(c, r)] = 10 * std::sin(c * 0.01) + r;
    const std::vector<float> field(dem.size(), 50.f);
    std::vector<std::uint32_t> pixels(dem.size());
    for (std::size_t i = 0; i < pixels.size(); ++i)
        pixels[i] = 1 + static_cast<std::uint32_t>(i % std::size_t(dem.width)) / 1000;
    const auto image = io::render_preview(dem, field, pixels);
    CHECK(image.width == 3001);  // 9001 / 3, rounded up
    CHECK(image.width <= 4096);
    CHECK(image.height == 5);
    CHECK(image.frame.metres_per_pixel == Approx(3.0));
    CHECK(image.frame.ticks.empty());  // no CRS: no longitude or latitude
    CHECK_FALSE(image.frame.has_north);
    const auto framed = io::frame_preview(image);
    CHECK(framed.width > image.width);
    CHECK(framed.height >= image.height + 14 * framed.font_size);  // room for the colour bar
}

TEST_CASE("sweep.png: axis titles and legend text", "[write_sweep_plot]") {
    const auto dir = test::scratch_dir("write_sweep_plot");
    const std::vector<double> ratios{0.1, 0.5, 2}, counts{300, 120, 40}, areas{2e6, 5e6, 1.5e7};
    io::write_sweep_plot(ratios, counts, areas, (dir / "sweep.png").string(), false);
    const auto png = read_png((dir / "sweep.png").string());
    CHECK(png.width == 900);
    CHECK(png.height == 560);
    // The x axis's title below the tick values, the legend above the plot.
    CHECK(dark_pixels(png, 300, 520, 600, 550) > 100);
    CHECK(dark_pixels(png, 150, 10, 400, 35) > 50);
    {
        const ScopedEnv no_font("TERRAIN_FONT", (dir / "missing.ttf").c_str());
        io::write_sweep_plot(ratios, counts, areas, (dir / "bare.png").string(), false);
    }
    const auto bare = read_png((dir / "bare.png").string());
    CHECK(dark_pixels(bare, 300, 520, 600, 550) == 0);
    CHECK(dark_pixels(bare, 150, 10, 400, 35) == 0);
}

TEST_CASE("preview.png on a UTM tile: north leans by the grid convergence, ticks follow it",
          "[write_preview][real_data]") {
    const auto path = test::real_data("earth/bigtujunga_srtm30m_utm11.tif");
    REQUIRE(path.has_value());  // tests/data is in the repository
    const Dem dem = io::read_dem(*path);
    const std::vector<float> field(dem.size(), 50.f);
    const std::vector<std::uint32_t> pixels(dem.size(), 1);
    const auto image = io::render_preview(dem, field, pixels);
    const auto& frame = image.frame;
    // West of zone 11's central meridian (117°W) at 34.3°N the meridians lean east going north
    // by (118.15 - 117) * sin(34.3°) = 0.65 degrees.
    REQUIRE(frame.has_north);
    CHECK(frame.north_degrees == Approx(0.65).margin(0.05));
    CHECK(frame.scale_note.find("34.3°N") != std::string::npos);
    CHECK(frame.metres_per_pixel == Approx(dem.georef.pixel_width_m));
    // Latitude ticks are lower on the right edge than on the left, by the map's width times
    // tan(0.65°) (about 14 map pixels over 1197); longitudes are west and grow eastwards.
    std::map<std::string, double> left, right;
    std::vector<double> bottom_lons;
    for (const auto& t : frame.ticks) {
        if (t.edge == 3) left[t.label] = t.position;
        if (t.edge == 1) right[t.label] = t.position;
        if (t.edge % 2 == 0) CHECK(t.label.back() == 'W');
        if (t.edge == 2) bottom_lons.push_back(t.position);
    }
    REQUIRE(left.count("34.30°N") == 1);
    REQUIRE(right.count("34.30°N") == 1);
    CHECK(right["34.30°N"] - left["34.30°N"] ==
          Approx(image.width * std::tan(0.65 * 3.14159265358979 / 180)).margin(2));
    CHECK(bottom_lons.size() >= 3);
    CHECK(std::is_sorted(bottom_lons.begin(), bottom_lons.end()));
}
