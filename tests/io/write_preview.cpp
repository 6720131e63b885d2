#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

#include "support/segment_support.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/io/write_preview.hpp"

using namespace terrain;

TEST_CASE("preview.png: enlarged to about 1024 pixels, boundaries black, NoData transparent",
          "[write_preview]") {
    Dem vesta = test::crop(io::read_dem(test::sample("vesta_hamo_tile.lbl")), 0, 0, 64, 48);
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 8; ++c) vesta.values[vesta.index(c, r)] = std::nan("");
    const auto t = test::segment_tile(vesta, test::voronoi_cells(vesta, 3, 2));
    const auto dir = test::scratch_dir("write_preview");
    const auto path = (dir / "preview.png").string();
    const auto field = field::field_to_pixels(t.mesh, t.dem, t.field);
    io::write_preview_png(t.dem, field, t.pixels, path, false);

    auto in = OIIO::ImageInput::open(path);
    REQUIRE(in);
    const auto& spec = in->spec();
    const int k = 16;  // 1024 / 64
    CHECK(spec.width == 64 * k);
    CHECK(spec.height == 48 * k);
    CHECK(spec.nchannels == 4);
    std::vector<std::uint8_t> image(std::size_t(spec.width) * spec.height * 4);
    REQUIRE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, image.data()));
    in->close();
    auto pixel = [&](int x, int y) {
        const auto i = (std::size_t(y) * spec.width + x) * 4;
        return std::array<int, 4>{image[i], image[i + 1], image[i + 2], image[i + 3]};
    };
    // NoData (top-left block) is transparent; labelled pixels are opaque.
    CHECK(pixel(3 * k, 2 * k)[3] == 0);
    CHECK(pixel(40 * k + 3, 30 * k + 3)[3] == 255);
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
