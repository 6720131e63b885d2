// Every valid pixel labelled: pixels in no triangle (isolated, or touching the others only
// at a corner) join a neighbouring region or form their own (segment::label_pixels), and the
// region table counts them; through `terrain segment`, read back from labels.tif with GDAL.
#include <cpl_json.h>
#include <gdal_priv.h>
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <set>

#include "support/segment_support.hpp"
#include "support/test_support.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;
namespace fs = std::filesystem;

namespace {

// The labels of pixel p's valid 8-neighbours among `pixels`.
std::set<std::uint32_t> neighbour_labels(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                                         int col, int row) {
    std::set<std::uint32_t> out;
    for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
            const int c = col + dc, r = row + dr;
            if ((dr || dc) && c >= 0 && r >= 0 && c < dem.width && r < dem.height &&
                pixels[dem.index(c, r)] != 0)
                out.insert(pixels[dem.index(c, r)]);
        }
    return out;
}

}  // namespace

TEST_CASE("label_pixels: a checkerboard of valid pixels is labelled everywhere", "[regions]") {
    // 40 x 30 pixels of the Vesta sample: the left 16 columns whole, the rest a checkerboard
    // (each valid pixel touches the others at its corners only), and far off the checkerboard
    // two lone groups: one pixel, and a diagonal pair.
    Dem dem = test::crop(io::read_dem(test::sample("vesta_hamo_tile.lbl")), 100, 100, 40, 30);
    for (int r = 0; r < dem.height; ++r)
        for (int c = 17; c < dem.width; ++c)
            if ((r + c) % 2 == 1 || r >= 24) dem.values[dem.index(c, r)] = std::nan("");
    for (int r = 24; r < dem.height; ++r)
        for (int c = 0; c < dem.width; ++c)
            if (c >= 12) dem.values[dem.index(c, r)] = std::nan("");
    dem.values[dem.index(30, 27)] = 1e3 + dem.body.semi_major_axis;
    dem.values[dem.index(36, 26)] = dem.values[dem.index(37, 27)] = 2e3 + dem.body.semi_major_axis;
    // Regions of the meshed pixels: top and bottom halves.
    const auto t = test::segment_tile(dem, [](int, int row) { return row < 15 ? 1u : 2u; });
    REQUIRE(t.region_count == 2);
    const auto vertex = mesh::pixel_to_vertex(t.mesh, t.dem);
    std::size_t valid = 0, unmeshed = 0;
    for (int r = 0; r < dem.height; ++r)
        for (int c = 0; c < dem.width; ++c) {
            const auto p = dem.index(c, r);
            INFO("pixel " << c << "," << r);
            CHECK((t.pixels[p] == 0) == !dem.valid(c, r));
            if (!dem.valid(c, r)) continue;
            ++valid;
            if (vertex[p] >= 0) {
                CHECK(t.pixels[p] == t.labels[std::size_t(vertex[p])]);
                continue;
            }
            ++unmeshed;
            if (c >= 18 && r < 24) {
                // The checkerboard joins a neighbouring region: a label of a neighbour, the
                // halves' own away from the line between them (ties going to the lower
                // label, that line drifts down by at most one row per column).
                CHECK(neighbour_labels(dem, t.pixels, c, r).count(t.pixels[p]) == 1);
                if (r < 13) CHECK(t.pixels[p] == 1);
                if (r > c) CHECK(t.pixels[p] == 2);
            }
        }
    CHECK(unmeshed > 100);
    // The lone groups: regions of their own, numbered after the mesh's, in row-major order.
    CHECK(t.pixels[dem.index(36, 26)] == 3);
    CHECK(t.pixels[dem.index(37, 27)] == 3);
    CHECK(t.pixels[dem.index(30, 27)] == 4);
    // The region table counts every pixel; the lone groups have no vertex and no neighbour.
    REQUIRE(t.graph.regions.size() == 4);
    std::size_t counted = 0;
    for (const auto& r : t.graph.regions) counted += r.pixel_count;
    CHECK(counted == valid);
    CHECK(t.graph.regions[2].pixel_count == 2);
    CHECK(t.graph.regions[2].vertex_count == 0);
    CHECK(t.graph.regions[2].neighbor_count == 0);
    CHECK(t.graph.regions[2].area_m2 == Approx(test::labelled_area(dem, t.pixels, 3)));
    CHECK(t.graph.regions[3].pixel_count == 1);
    CHECK(std::isnan(t.graph.regions[3].field_mean));
    // No field value, so no landform class (not the class of a shape index of 50).
    CHECK(t.graph.regions[3].landform == segment::Landform::unknown);
    CHECK(std::string(segment::to_string(t.graph.regions[3].landform)) == "unknown");
    CHECK(t.graph.regions[0].landform != segment::Landform::unknown);
    for (std::uint32_t id = 1; id <= 4; ++id)
        CHECK(t.graph.regions[id - 1].area_m2 == Approx(test::labelled_area(dem, t.pixels, id)));
    // The same labels again: the rule is deterministic.
    CHECK(segment::label_pixels(t.mesh, t.dem, t.labels) == t.pixels);
}

TEST_CASE("terrain segment labels every valid pixel of a country-shaped DEM", "[cli][regions]") {
    GDALAllRegister();
    const auto dir = test::scratch_dir("pixel_labels_country");
    // A real tile (the Moon at 4 pixels per degree) inside an irregular border, NoData
    // around it, with pixels outside the border that touch it at a corner only and an
    // island of one pixel.
    const auto sample = test::sample("moon_ldem4_copernicus.tif");
    std::unique_ptr<GDALDataset> src(
        GDALDataset::FromHandle(GDALOpen(sample.c_str(), GA_ReadOnly)));
    REQUIRE(src);
    const int w = src->GetRasterXSize(), h = src->GetRasterYSize();
    std::vector<double> v(static_cast<std::size_t>(w) * h);
    REQUIRE(src->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, w, h, v.data(), w, h, GDT_Float64, 0,
                                            0) == CE_None);
    const double nodata = -32768;
    const double cx = w / 2.0, cy = h / 2.0;
    auto inside = [&](int c, int r) {
        const double a = std::atan2(r + 0.5 - cy, c + 0.5 - cx);
        const double radius =
            0.35 * std::min(w, h) * (1 + 0.25 * std::sin(3 * a) + 0.1 * std::cos(7 * a));
        return std::hypot(c + 0.5 - cx, r + 0.5 - cy) < radius;
    };
    std::vector<std::uint8_t> keep(v.size(), 0);
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) keep[std::size_t(r * w + c)] = inside(c, r);
    // Corner-only pixels: outside the border, diagonal to a pixel inside, with no valid
    // 4-neighbour.
    int corner_only = 0;
    auto valid = [&](int c, int r) {
        return c >= 0 && r >= 0 && c < w && r < h && keep[std::size_t(r * w + c)];
    };
    for (int r = 1; r < h - 1 && corner_only < 6; r += 3)
        for (int c = 1; c < w - 1 && corner_only < 6; ++c) {
            if (valid(c, r) || valid(c - 1, r) || valid(c + 1, r) || valid(c, r - 1) ||
                valid(c, r + 1) || valid(c - 1, r - 1) || valid(c + 1, r - 1) ||
                valid(c - 1, r + 1))
                continue;
            if (!valid(c + 1, r + 1)) continue;
            keep[std::size_t(r * w + c)] = 1;
            ++corner_only;
        }
    REQUIRE(corner_only >= 3);
    // An island: one pixel with NoData all around it.
    keep[std::size_t(2 * w + 2)] = 1;
    for (std::size_t i = 0; i < v.size(); ++i)
        if (!keep[i]) v[i] = nodata;
    test::RasterSpec spec;
    spec.width = w;
    spec.height = h;
    spec.values = v;
    spec.nodata = nodata;
    spec.crs = src->GetProjectionRef();
    double gt[6];
    REQUIRE(src->GetGeoTransform(gt) == CE_None);
    spec.geotransform.assign(gt, gt + 6);
    const auto country = test::write_raster(dir / "country.tif", spec);

    const auto out = dir / "seg";
    const auto r = test::run_cli({"segment", country, "-o", out.string(), "-q", "--overwrite"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    std::unique_ptr<GDALDataset> labels(
        GDALDataset::FromHandle(GDALOpen((out / "labels.tif").string().c_str(), GA_ReadOnly)));
    REQUIRE(labels);
    std::vector<std::uint32_t> px(v.size());
    REQUIRE(labels->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, w, h, px.data(), w, h, GDT_UInt32, 0,
                                               0) == CE_None);
    std::size_t valid_pixels = 0;
    std::uint32_t top = 0;
    for (std::size_t i = 0; i < px.size(); ++i) {
        INFO("pixel " << i % w << "," << i / w);
        CHECK((px[i] != 0) == (keep[i] != 0));
        valid_pixels += keep[i];
        top = std::max(top, px[i]);
    }
    // The island is a region of its own, the last; the table counts every valid pixel.
    CHECK(px[std::size_t(2 * w + 2)] == top);
    CPLJSONDocument run;
    REQUIRE(run.Load((out / "run.json").string()));
    CHECK(run.GetRoot().GetObj("counts").GetLong("regions") == top);
    CPLJSONDocument adjacency;
    REQUIRE(adjacency.Load((out / "adjacency.json").string()));
    const auto regions = adjacency.GetRoot().GetArray("nodes");
    REQUIRE(regions.Size() == int(top));
    std::size_t counted = 0;
    for (int i = 0; i < regions.Size(); ++i)
        counted += std::size_t(regions[i].GetLong("pixel_count"));
    CHECK(counted == valid_pixels);
    CHECK(regions[int(top) - 1].GetLong("pixel_count") == 1);
    CHECK(regions[int(top) - 1].GetLong("vertex_count") == 0);
    CHECK(regions[int(top) - 1].GetString("landform") == "unknown");
}
