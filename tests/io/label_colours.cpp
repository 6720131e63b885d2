#include <gdal_priv.h>
#include <gdal_rat.h>
#include <catch2/catch.hpp>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "support/segment_support.hpp"
#include "support/test_support.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/io/region_colour.hpp"
#include "terrain/io/write_label_raster.hpp"
#include "terrain/io/write_label_stack.hpp"

using namespace terrain;

namespace {

std::string text_of(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

std::size_t count_of(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// Runs a Python snippet with Debian's python3 (python3-rasterio); its exit status.
int python(const std::string& code) {
    const auto script = test::scratch_dir("label_colours_python") / "check.py";
    std::ofstream(script) << code;
    return std::system(("/usr/bin/python3 " + script.string()).c_str());
}

// Every pixel of a crop of the Vesta sample its own region: the crop, its labels and graph.
struct PixelRegions {
    Dem dem;
    std::vector<std::uint32_t> pixels;
    segment::RegionGraph graph;
};
PixelRegions pixel_regions(int width, int height) {
    PixelRegions p{
        test::crop(io::read_dem(test::sample("vesta_hamo_tile.lbl")), 0, 0, width, height), {}, {}};
    p.pixels.resize(p.dem.size());
    p.graph.point_frame = segment::PointFrame::map;
    for (std::size_t i = 0; i < p.dem.size(); ++i) {
        p.pixels[i] = static_cast<std::uint32_t>(i + 1);
        segment::Region r;
        r.id = p.pixels[i];
        r.pixel_count = 1;
        r.vertex_count = 1;
        r.area_m2 = 1;
        r.field_mean = double(i % 101);
        r.landform = segment::landform_of(r.field_mean);
        p.graph.regions.push_back(r);
    }
    return p;
}

}  // namespace

TEST_CASE("labels.tif with 1200 regions: UInt16 with a colour table, a valid COG",
          "[write_label_raster][label_colours]") {
    const auto p = pixel_regions(40, 30);  // 1200 regions
    const auto dir = test::scratch_dir("label_colours_uint16");
    const auto path = (dir / "labels.tif").string();
    io::write_label_raster(p.dem, p.pixels, p.graph, path, false);
    GDALAllRegister();
    {
        std::unique_ptr<GDALDataset> ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
        REQUIRE(ds);
        GDALRasterBand* band = ds->GetRasterBand(1);
        CHECK(band->GetRasterDataType() == GDT_UInt16);
        const GDALColorTable* table = band->GetColorTable();
        REQUIRE(table);
        const auto c = io::region_colour(1200);
        const GDALColorEntry* e = table->GetColorEntry(1200);
        REQUIRE(e);
        CHECK((e->c1 == c[0] && e->c2 == c[1] && e->c3 == c[2]));
        std::uint32_t last = 0;
        REQUIRE(band->RasterIO(GF_Read, 39, 29, 1, 1, &last, 1, 1, GDT_UInt32, 0, 0) == CE_None);
        CHECK(last == 1200);
    }
    // GDAL's own validator of the Cloud-Optimized GeoTIFF layout (python3-gdal's sample).
    CHECK(python("import sys\n"
                 "from osgeo_utils.samples import validate_cloud_optimized_geotiff as v\n"
                 "warnings, errors, details = v.validate('" +
                 path +
                 "', full_check=True)\n"
                 "sys.exit(1 if errors else 0)\n") == 0);
}

TEST_CASE(
    "labels.tif beyond 65535 regions: UInt32, no colour table, an attribute table and a "
    "style, read by rasterio",
    "[write_label_raster][label_colours]") {
    // Every pixel of a 300 x 240 Vesta crop its own region: 72000 regions.
    const auto [dem, pixels, graph] = pixel_regions(300, 240);
    REQUIRE(graph.regions.size() == 72000);
    const auto dir = test::scratch_dir("label_colours_uint32");
    const auto path = (dir / "labels.tif").string();
    io::write_label_raster(dem, pixels, graph, path, false);

    GDALAllRegister();
    {
        std::unique_ptr<GDALDataset> ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
        REQUIRE(ds);
        GDALRasterBand* band = ds->GetRasterBand(1);
        CHECK(band->GetRasterDataType() == GDT_UInt32);
        CHECK(band->GetColorTable() == nullptr);
        const GDALRasterAttributeTable* rat = band->GetDefaultRAT();
        REQUIRE(rat);
        CHECK(rat->GetRowCount() == 72000);
        std::uint32_t last = 0;
        REQUIRE(band->RasterIO(GF_Read, 299, 239, 1, 1, &last, 1, 1, GDT_UInt32, 0, 0) == CE_None);
        CHECK(last == 72000);
    }
    const auto style = text_of(dir / "labels.qml");
    CHECK(count_of(style, "<paletteEntry ") == 72000);
    const auto c = io::region_colour(71999);
    char colour[8];
    std::snprintf(colour, sizeof colour, "#%02x%02x%02x", c[0], c[1], c[2]);
    CHECK(style.find("value=\"71999\" color=\"" + std::string(colour) + "\"") != std::string::npos);
    // rasterio reads the values as uint32 and finds no colour map.
    CHECK(python("import rasterio\n"
                 "with rasterio.open('" +
                 path +
                 "') as r:\n"
                 "    a = r.read(1)\n"
                 "    assert r.dtypes[0] == 'uint32', r.dtypes\n"
                 "    assert a.max() == 72000 and a.min() == 1, (a.min(), a.max())\n"
                 "    try:\n"
                 "        r.colormap(1)\n"
                 "        raise SystemExit(3)\n"
                 "    except ValueError:\n"
                 "        pass\n") == 0);
}

TEST_CASE(
    "the sweep's labels.tif: band 1's colour table in the .aux.xml, a style, the GeoTIFF "
    "unchanged",
    "[write_label_stack][label_colours]") {
    const Dem vesta =
        test::crop(io::read_dem(test::sample("vesta_hamo_tile.lbl")), 100, 80, 48, 40);
    const auto a = test::segment_tile(vesta, test::voronoi_cells(vesta, 4, 3));
    const auto b = test::segment_tile(vesta, test::voronoi_cells(vesta, 2, 2));
    const std::vector<std::vector<std::uint32_t>> bands{a.pixels, b.pixels};
    const std::vector<std::string> names{"area_ratio=0.1", "area_ratio=1"};
    const auto dir = test::scratch_dir("label_colours_stack");
    const auto plain = (dir / "plain.tif").string(), coloured = (dir / "labels.tif").string();
    io::write_label_stack(vesta, bands, names, plain, false);
    io::write_label_stack(vesta, bands, names, {&a.graph, &b.graph}, coloured, false);
    // The colours and attribute tables live beside the GeoTIFF, which is the same bytes.
    CHECK(test::file_bytes(plain) == test::file_bytes(coloured));
    CHECK_FALSE(std::filesystem::exists(dir / "plain.qml"));

    GDALAllRegister();
    std::unique_ptr<GDALDataset> ds(GDALDataset::Open(coloured.c_str(), GDAL_OF_RASTER));
    REQUIRE(ds);
    GDALRasterBand* band = ds->GetRasterBand(1);
    CHECK(band->GetColorInterpretation() == GCI_PaletteIndex);
    const GDALColorTable* table = band->GetColorTable();
    REQUIRE(table);
    CHECK(table->GetColorEntryCount() == static_cast<int>(a.graph.regions.size()) + 1);
    for (const auto& r : a.graph.regions) {
        const auto expected = io::region_colour(r.id);
        const GDALColorEntry* e = table->GetColorEntry(static_cast<int>(r.id));
        REQUIRE(e);
        CHECK(std::array<int, 4>{e->c1, e->c2, e->c3, e->c4} ==
              std::array<int, 4>{expected[0], expected[1], expected[2], expected[3]});
    }
    const GDALColorEntry* none = table->GetColorEntry(0);
    REQUIRE(none);
    CHECK(none->c4 == 0);
    for (int k = 1; k <= 2; ++k) {
        const GDALRasterAttributeTable* rat = ds->GetRasterBand(k)->GetDefaultRAT();
        REQUIRE(rat);
        CHECK(rat->GetRowCount() == static_cast<int>((k == 1 ? a : b).graph.regions.size()));
    }
    // rasterio finds band 1's colour map, with each region's colour.
    const auto c = io::region_colour(a.graph.regions.back().id);
    CHECK(python("import rasterio\n"
                 "with rasterio.open('" +
                 coloured +
                 "') as r:\n"
                 "    m = r.colormap(1)\n"
                 "    assert len(m) == " +
                 std::to_string(a.graph.regions.size() + 1) +
                 ", len(m)\n"
                 "    assert m[" +
                 std::to_string(a.graph.regions.back().id) + "] == (" + std::to_string(c[0]) +
                 ", " + std::to_string(c[1]) + ", " + std::to_string(c[2]) + ", " +
                 std::to_string(c[3]) + "), m\n") == 0);
    const auto style = text_of(dir / "labels.qml");
    CHECK(style.find("type=\"paletted\" band=\"1\"") != std::string::npos);
    CHECK(count_of(style, "<paletteEntry ") == a.graph.regions.size());
}
