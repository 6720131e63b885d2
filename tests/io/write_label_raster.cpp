#include <gdal_priv.h>
#include <gdal_rat.h>
#include <ogr_spatialref.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>

#include "support/segment_support.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/io/region_colour.hpp"
#include "terrain/io/write_label_raster.hpp"

using namespace terrain;

namespace {

// A Vesta crop with a NoData hole, cut into Voronoi cells.
test::SegmentedTile vesta_tile() {
    Dem vesta = test::crop(io::read_dem(test::sample("vesta_hamo_tile.lbl")), 200, 150, 40, 32);
    for (int r = 10; r < 16; ++r)
        for (int c = 5; c < 12; ++c) vesta.values[vesta.index(c, r)] = std::nan("");
    return test::segment_tile(vesta, test::voronoi_cells(vesta, 4, 3));
}

}  // namespace

TEST_CASE("labels.tif: UInt16 on the DEM's grid, labels where the DEM is valid, NoData 0",
          "[write_label_raster]") {
    const auto t = vesta_tile();
    const auto dir = test::scratch_dir("write_label_raster");
    const auto path = (dir / "labels.tif").string();
    io::write_label_raster(t.dem, t.pixels, t.graph, path, false);

    GDALAllRegister();
    std::unique_ptr<GDALDataset> ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
    REQUIRE(ds);
    CHECK(ds->GetRasterXSize() == t.dem.width);
    CHECK(ds->GetRasterYSize() == t.dem.height);
    GeoTransform gt{};
    REQUIRE(ds->GetGeoTransform(gt.data()) == CE_None);
    CHECK(gt == t.dem.transform);
    // The DEM's projection on Vesta's IAU_2015 sphere (the same radius).
    OGRSpatialReference dem_srs, vesta;
    dem_srs.SetFromUserInput(t.dem.crs_wkt.c_str());
    REQUIRE(vesta.SetFromUserInput("IAU_2015:200000400") == OGRERR_NONE);
    REQUIRE(dem_srs.CopyGeogCSFrom(&vesta) == OGRERR_NONE);
    REQUIRE(ds->GetSpatialRef());
    CHECK(ds->GetSpatialRef()->IsSame(&dem_srs));
    GDALRasterBand* band = ds->GetRasterBand(1);
    CHECK(band->GetRasterDataType() == GDT_UInt16);
    // A Cloud-Optimized GeoTIFF (GDAL's COG driver names its layout; 40 x 32 pixels need
    // no overview).
    const char* layout = ds->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE");
    CHECK(std::string(layout ? layout : "") == "COG");
    CHECK(band->GetOverviewCount() == 0);
    int has_nodata = 0;
    CHECK(band->GetNoDataValue(&has_nodata) == 0);
    CHECK(has_nodata);
    std::vector<std::uint32_t> read(t.dem.size());
    REQUIRE(band->RasterIO(GF_Read, 0, 0, t.dem.width, t.dem.height, read.data(), t.dem.width,
                           t.dem.height, GDT_UInt32, 0, 0) == CE_None);
    CHECK(read == t.pixels);
    // Every valid pixel is labelled, and only them (this crop has no isolated pixel).
    for (std::size_t p = 0; p < read.size(); ++p)
        CHECK((read[p] != 0) == !std::isnan(t.dem.values[p]));

    // The attribute table: one row per region, its properties and its colour.
    GDALRasterAttributeTable* rat = band->GetDefaultRAT();
    REQUIRE(rat);
    REQUIRE(rat->GetRowCount() == int(t.region_count));
    auto column = [&](const char* name) {
        for (int c = 0; c < rat->GetColumnCount(); ++c)
            if (std::string(rat->GetNameOfCol(c)) == name) return c;
        FAIL("no column " << name);
        return -1;
    };
    CHECK(rat->GetUsageOfCol(column("id")) == GFU_MinMax);
    CHECK(rat->GetUsageOfCol(column("pixel_count")) == GFU_PixelCount);
    CHECK(rat->GetUsageOfCol(column("landform")) == GFU_Name);
    CHECK(rat->GetTypeOfCol(column("area_m2")) == GFT_Real);
    for (int row = 0; row < rat->GetRowCount(); ++row) {
        const auto& r = t.graph.regions[std::size_t(row)];
        CHECK(rat->GetValueAsInt(row, column("id")) == int(r.id));
        CHECK(rat->GetValueAsInt(row, column("pixel_count")) == int(r.pixel_count));
        CHECK(rat->GetValueAsDouble(row, column("area_m2")) == Approx(r.area_m2));
        CHECK(rat->GetValueAsDouble(row, column("field_mean")) == Approx(r.field_mean));
        CHECK(rat->GetValueAsDouble(row, column("field_min")) == Approx(r.field_min));
        CHECK(rat->GetValueAsDouble(row, column("field_max")) == Approx(r.field_max));
        CHECK(std::string(rat->GetValueAsString(row, column("landform"))) ==
              segment::to_string(r.landform));
        CHECK(rat->GetRowOfValue(double(r.id)) == row);
        const auto colour = io::region_colour(r.id);
        CHECK(rat->GetValueAsInt(row, column("Red")) == colour[0]);
        CHECK(rat->GetValueAsInt(row, column("Green")) == colour[1]);
        CHECK(rat->GetValueAsInt(row, column("Blue")) == colour[2]);
        CHECK(rat->GetValueAsInt(row, column("Alpha")) == 255);
    }
    // The band's colour table holds the region colours; GDAL also turns the RAT's colours into
    // the same table indexed by id.
    const GDALColorTable* band_table = band->GetColorTable();
    REQUIRE(band_table);
    CHECK(band->GetColorInterpretation() == GCI_PaletteIndex);
    CHECK(band_table->GetColorEntry(0)->c4 == 0);
    std::unique_ptr<GDALColorTable> table(rat->TranslateToColorTable(-1));
    REQUIRE(table);
    CHECK(table->GetColorEntryCount() == int(t.region_count) + 1);
    for (std::uint32_t id = 1; id <= t.region_count; ++id) {
        const GDALColorEntry* e = band_table->GetColorEntry(int(id));
        const auto colour = io::region_colour(id);
        CHECK(std::array<int, 4>{e->c1, e->c2, e->c3, e->c4} ==
              std::array<int, 4>{colour[0], colour[1], colour[2], colour[3]});
    }
    for (std::uint32_t id = 1; id <= t.region_count; ++id) {
        const GDALColorEntry* e = table->GetColorEntry(int(id));
        const auto colour = io::region_colour(id);
        CHECK(std::array<int, 4>{e->c1, e->c2, e->c3, e->c4} ==
              std::array<int, 4>{colour[0], colour[1], colour[2], colour[3]});
    }
    CHECK(std::filesystem::exists(path + ".aux.xml"));
    // The QGIS style beside it: one palette entry per region.
    const auto qml = test::file_bytes(io::label_style_path(path));
    CHECK(io::label_style_path(path) == (dir / "labels.qml").string());
    CHECK(qml.find("type=\"paletted\"") != std::string::npos);
    std::size_t entries = 0;
    for (auto at = qml.find("<paletteEntry"); at != std::string::npos;
         at = qml.find("<paletteEntry", at + 1))
        ++entries;
    CHECK(entries == t.region_count);
}

TEST_CASE("labels.tif: colours are distinct and id 0 is transparent", "[write_label_raster]") {
    CHECK(io::region_colour(0) == std::array<std::uint8_t, 4>{0, 0, 0, 0});
    for (std::uint32_t id = 1; id < 200; ++id) {
        CHECK(io::region_colour(id)[3] == 255);
        CHECK(io::region_colour(id) != io::region_colour(id + 1));
    }
}

TEST_CASE("labels.tif: same bytes again, existing files kept unless overwrite, nothing left",
          "[write_label_raster]") {
    const auto t = vesta_tile();
    const auto dir = test::scratch_dir("write_label_raster_again");
    const auto path = (dir / "labels.tif").string();
    io::write_label_raster(t.dem, t.pixels, t.graph, path, false);
    const auto tif = test::file_bytes(path), aux = test::file_bytes(path + ".aux.xml");
    CHECK_THROWS_AS(io::write_label_raster(t.dem, t.pixels, t.graph, path, false), Error);
    std::filesystem::remove(path);
    // The sidecar alone also counts as an existing output.
    CHECK_THROWS_AS(io::write_label_raster(t.dem, t.pixels, t.graph, path, false), Error);
    io::write_label_raster(t.dem, t.pixels, t.graph, path, true);
    CHECK(test::file_bytes(path) == tif);
    CHECK(test::file_bytes(path + ".aux.xml") == aux);
    std::size_t files = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
        ++files;
        CHECK(e.path().filename().string()[0] != '.');
    }
    CHECK(files == 3);  // labels.tif, its .aux.xml and labels.qml
    CHECK_THROWS_AS(
        io::write_label_raster(t.dem, t.pixels, t.graph, (dir / "no/such/l.tif").string(), false),
        Error);
    const std::vector<std::uint32_t> wrong(5, 1);
    CHECK_THROWS_AS(io::write_label_raster(t.dem, wrong, t.graph, path, true), Error);
}

TEST_CASE("labels.tif reports GDAL's progress, and a cancel leaves no file",
          "[write_label_raster]") {
    // On a global grid of 265 M pixels writing the tiles and overviews takes a minute: GDAL's
    // own progress goes to the callback.
    // The whole 512 x 512 tile: GDAL reports tile by tile (a tiny grid gets one call).
    const Dem vesta = io::read_dem(test::sample("vesta_hamo_tile.lbl"));
    const auto t = test::segment_tile(vesta, test::voronoi_cells(vesta, 6, 5));
    const auto dir = test::scratch_dir("write_label_raster_progress");
    const auto path = (dir / "labels.tif").string();
    std::vector<double> seen;
    io::write_label_raster(t.dem, t.pixels, t.graph, path, false,
                           [&](double f, std::string_view message) {
                               CHECK(message == "write");
                               seen.push_back(f);
                               return true;
                           });
    INFO(seen.size() << " calls, the last " << seen.back());
    CHECK(seen.size() >= 3);
    CHECK(std::is_sorted(seen.begin(), seen.end()));
    CHECK(seen.back() == Approx(1.0));
    const auto written = test::file_bytes(path);
    // The same bytes as without a callback.
    const auto again = (dir / "again.tif").string();
    io::write_label_raster(t.dem, t.pixels, t.graph, again, false);
    CHECK(test::file_bytes(again) == written);
    // A callback that cancels halfway: terrain::Error, and neither the raster nor its sidecars.
    const auto cancelled = (dir / "cancelled.tif").string();
    CHECK_THROWS_AS(io::write_label_raster(t.dem, t.pixels, t.graph, cancelled, false,
                                           [](double f, std::string_view) { return f < 0.5; }),
                    Error);
    CHECK_FALSE(std::filesystem::exists(cancelled));
    CHECK_FALSE(std::filesystem::exists(cancelled + ".aux.xml"));
    CHECK_FALSE(std::filesystem::exists(io::label_style_path(cancelled)));
    for (const auto& e : std::filesystem::directory_iterator(dir))
        CHECK(e.path().filename().string()[0] != '.');
}
