#include <catch2/catch.hpp>

#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/io/write_pds3_dem.hpp"
#include "terrain/synth/crater_field.hpp"

namespace fs = std::filesystem;
using terrain::io::Pds3DemOptions;
using terrain::io::write_pds3_dem;

namespace {

terrain::Dem tile(int width = 96, int height = 80) {
    terrain::synth::VestaTileOptions o;
    o.width = width;
    o.height = height;
    o.seed = 42;
    return terrain::synth::generate_vesta_tile(o);
}

std::string slurp(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The value of the first `KEY = VALUE` line of a PDS3 label with this key.
std::string label_value(const std::string& label, const std::string& key) {
    std::size_t start = 0;
    while (start < label.size()) {
        std::size_t end = label.find("\r\n", start);
        if (end == std::string::npos) end = label.size();
        const std::string line = label.substr(start, end - start);
        const std::size_t eq = line.find(" = ");
        if (eq != std::string::npos) {
            const std::size_t k0 = line.find_first_not_of(' ');
            const std::size_t k1 = line.find_last_not_of(' ', eq);
            if (line.substr(k0, k1 + 1 - k0) == key) return line.substr(eq + 3);
        }
        start = end + 2;
    }
    return "(missing " + key + ")";
}

std::unique_ptr<GDALDataset> open(const std::string& path) {
    GDALAllRegister();
    return std::unique_ptr<GDALDataset>(
        GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY));
}

// The files next to `dir` that are not `names` (leftover temporary files).
std::vector<std::string> listing(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace

TEST_CASE("GDAL's PDS driver reads back the geotransform, scaling and CRS", "[pds3]") {
    const auto dem = tile();
    const auto dir = terrain::test::scratch_dir("pds3_gdal");
    const std::string label = (dir / "vesta.lbl").string();
    write_pds3_dem(dem, label, {});
    CHECK(listing(dir) == std::vector<std::string>{"vesta.img", "vesta.lbl"});

    const auto ds = open(label);
    REQUIRE(ds);
    CHECK(std::string(ds->GetDriver()->GetDescription()) == "PDS");
    CHECK(ds->GetRasterXSize() == 96);
    CHECK(ds->GetRasterYSize() == 80);
    double gt[6];
    REQUIRE(ds->GetGeoTransform(gt) == CE_None);
    for (int i = 0; i < 6; ++i) CHECK(gt[i] == Approx(dem.transform[i]).epsilon(1e-9).margin(1e-9));

    GDALRasterBand* band = ds->GetRasterBand(1);
    CHECK(band->GetRasterDataType() == GDT_Int16);
    int has = 0;
    CHECK(band->GetScale(&has) == 2.0);
    CHECK(has);
    CHECK(band->GetOffset(&has) == 255000.0);
    CHECK(has);
    CHECK(band->GetNoDataValue(&has) == -32768.0);
    CHECK(has);

    const OGRSpatialReference* srs = ds->GetSpatialRef();
    REQUIRE(srs);
    CHECK(srs->IsProjected());
    CHECK(srs->GetSemiMajor() == 255000.0);
    CHECK(srs->GetInvFlattening() == 0.0);
    CHECK(std::string(srs->GetAttrValue("PROJECTION")) == SRS_PT_EQUIRECTANGULAR);
    CHECK(srs->GetNormProjParm(SRS_PP_STANDARD_PARALLEL_1) == Approx(-30.0));
    CHECK(srs->GetNormProjParm(SRS_PP_CENTRAL_MERIDIAN) == Approx(150.0));
    CHECK_THAT(std::string(srs->GetAttrValue("DATUM")), Catch::Contains("VESTA"));
    CHECK_THAT(std::string(srs->GetAttrValue("SPHEROID")), Catch::Contains("VESTA"));

    // The same CRS as the tile's: coordinates transform one to one.
    OGRSpatialReference generated;
    REQUIRE(generated.importFromWkt(dem.crs_wkt.c_str()) == OGRERR_NONE);
    CHECK(srs->IsSame(&generated));
}

TEST_CASE("read_dem reads the values back exactly, as Vesta radii", "[pds3]") {
    const auto dem = tile();
    const auto dir = terrain::test::scratch_dir("pds3_values");
    const std::string label = (dir / "vesta.lbl").string();
    write_pds3_dem(dem, label, {});
    const auto back = terrain::io::read_dem(label);
    CHECK(back.body.name == "Vesta");
    CHECK(back.body.semi_major_axis == 255000.0);
    CHECK(back.elevation == terrain::ElevationKind::radius);
    CHECK(back.elevation_detected);
    REQUIRE(back.values.size() == dem.values.size());
    CHECK(back.values == dem.values);  // exact: DN * 2 + 255000 both ways
}

TEST_CASE("the image is MSB Int16 DNs and the label a PDS3 DEM label", "[pds3]") {
    auto dem = tile(40, 30);
    dem.values[dem.index(3, 2)] = std::numeric_limits<double>::quiet_NaN();
    const auto dir = terrain::test::scratch_dir("pds3_layout");
    const std::string label_path = (dir / "TILE.LBL").string();
    write_pds3_dem(dem, label_path, {});
    CHECK(terrain::io::pds3_image_path(label_path) == (dir / "TILE.IMG").string());

    const std::string image = slurp(dir / "TILE.IMG");
    REQUIRE(image.size() == 40u * 30u * 2u);
    const auto dn = [&](int col, int row) {
        const std::size_t i = 2 * dem.index(col, row);
        return static_cast<std::int16_t>((static_cast<unsigned char>(image[i]) << 8) |
                                         static_cast<unsigned char>(image[i + 1]));
    };
    CHECK(dn(0, 0) * 2.0 + 255000.0 == dem.at(0, 0));
    CHECK(dn(39, 29) * 2.0 + 255000.0 == dem.at(39, 29));
    CHECK(dn(3, 2) == -32768);

    const std::string label = slurp(label_path);
    CHECK(label.rfind("PDS_VERSION_ID", 0) == 0);
    CHECK_THAT(label, Catch::Contains("\r\n") && Catch::EndsWith("\r\nEND\r\n"));
    const std::vector<std::pair<const char*, const char*>> expected{
        {"^IMAGE", "\"TILE.IMG\""},
        {"RECORD_TYPE", "FIXED_LENGTH"},
        {"RECORD_BYTES", "80"},
        {"FILE_RECORDS", "30"},
        {"TARGET_NAME", "VESTA"},
        {"LINES", "30"},
        {"LINE_SAMPLES", "40"},
        {"SAMPLE_TYPE", "MSB_INTEGER"},
        {"SAMPLE_BITS", "16"},
        {"UNIT", "METER"},
        {"SCALING_FACTOR", "2.0"},
        {"OFFSET", "255000.0"},
        {"MISSING_CONSTANT", "-32768"},
        {"MAP_PROJECTION_TYPE", "\"EQUIRECTANGULAR\""},
        {"A_AXIS_RADIUS", "255.0 <KM>"},
        {"B_AXIS_RADIUS", "255.0 <KM>"},
        {"C_AXIS_RADIUS", "255.0 <KM>"},
        {"POSITIVE_LONGITUDE_DIRECTION", "\"EAST\""},
        {"CENTER_LATITUDE", "-30.0 <DEG>"},
        {"CENTER_LONGITUDE", "150.0 <DEG>"},
        {"MAP_RESOLUTION", "64.0 <PIX/DEG>"},
        {"MAXIMUM_LATITUDE", "-29.765625 <DEG>"},  // 15 rows of 1/64 degree above -30
        {"MINIMUM_LATITUDE", "-30.234375 <DEG>"},
        {"LINE_PROJECTION_OFFSET", "-1905.5 <PIXEL>"},  // -29.765625 * 64 - 0.5
        {"SAMPLE_PROJECTION_OFFSET", "19.5 <PIXEL>"},
    };
    for (const auto& [key, value] : expected) CHECK(label_value(label, key) == value);
    CHECK_THAT(label_value(label, "MAP_SCALE"), Catch::StartsWith("0.0695404623841"));
    const double west = std::stod(label_value(label, "WESTERNMOST_LONGITUDE"));
    const double east = std::stod(label_value(label, "EASTERNMOST_LONGITUDE"));
    // 40 columns of 69.54 m at -30 degrees, centred on 150 E.
    CHECK(east - west == Approx(40.0 / 64.0 / std::cos(30.0 * std::numbers::pi / 180)));
    CHECK(0.5 * (east + west) == Approx(150.0));
    for (std::size_t start = 0, end; (end = label.find("\r\n", start)) != std::string::npos;
         start = end + 2)
        CHECK(end - start + 2 <= 80);  // PDS3 label lines fit 80 bytes with their CR LF

    // GDAL and read_dem see the NaN pixel as NoData.
    const auto back = terrain::io::read_dem(label_path);
    CHECK(std::isnan(back.at(3, 2)));
    CHECK(back.at(4, 2) == dem.at(4, 2));
    const auto ds = open(label_path);
    REQUIRE(ds);
    std::int16_t raw = 0;
    REQUIRE(ds->GetRasterBand(1)->RasterIO(GF_Read, 3, 2, 1, 1, &raw, 1, 1, GDT_Int16, 0, 0) ==
            CE_None);
    CHECK(raw == -32768);
}

TEST_CASE("an existing product is kept unless overwrite is set", "[pds3]") {
    const auto dem = tile(32, 32);
    const auto dir = terrain::test::scratch_dir("pds3_overwrite");
    const std::string label = (dir / "vesta.lbl").string();
    write_pds3_dem(dem, label, {});
    const std::string before = slurp(dir / "vesta.img");

    auto other = tile(32, 32);
    for (auto& v : other.values) v += 10.0;
    CHECK_THROWS_WITH(write_pds3_dem(other, label, {}),
                      Catch::Contains("already exists") && Catch::Contains("overwrit"));
    CHECK(slurp(dir / "vesta.img") == before);

    // Only the image there: still refused, and the label is not written.
    fs::remove(label);
    CHECK_THROWS_AS(write_pds3_dem(other, label, {}), terrain::Error);
    CHECK_FALSE(fs::exists(label));

    Pds3DemOptions replace;
    replace.overwrite = true;
    write_pds3_dem(other, label, replace);
    CHECK(terrain::io::read_dem(label).values == other.values);
    CHECK(listing(dir) == std::vector<std::string>{"vesta.img", "vesta.lbl"});
}

TEST_CASE("a directory that cannot be written gives terrain::Error", "[pds3]") {
    const auto dem = tile(16, 16);
    const auto dir = terrain::test::scratch_dir("pds3_unwritable");
    // A regular file where the directory should be.
    std::ofstream(dir / "file") << "not a directory";
    CHECK_THROWS_WITH(write_pds3_dem(dem, (dir / "file" / "x.lbl").string(), {}),
                      Catch::StartsWith("write:") && Catch::Contains("not a directory"));
    CHECK_THROWS_WITH(write_pds3_dem(dem, (dir / "missing" / "x.lbl").string(), {}),
                      Catch::Contains("does not exist"));
    // A read-only directory (root may write anywhere, so only checked for other users).
    const auto readonly = dir / "readonly";
    fs::create_directory(readonly);
    fs::permissions(readonly, fs::perms::owner_read | fs::perms::owner_exec);
    if (geteuid() != 0) {
        CHECK_THROWS_WITH(write_pds3_dem(dem, (readonly / "x.lbl").string(), {}),
                          Catch::StartsWith("write:") && Catch::Contains("cannot create"));
        CHECK(fs::is_empty(readonly));
    }
    fs::permissions(readonly, fs::perms::owner_all);
    CHECK(listing(dir) == std::vector<std::string>{"file", "readonly"});
}

TEST_CASE("DEMs that PDS3 cannot describe are refused", "[pds3]") {
    const auto dir = terrain::test::scratch_dir("pds3_refused");
    const auto path = (dir / "x.lbl").string();

    auto dem = tile(16, 16);
    CHECK_THROWS_WITH(write_pds3_dem(dem, (dir / "x.tif").string(), {}), Catch::Contains(".lbl"));

    auto stretched = dem;
    stretched.transform[5] *= 2;
    CHECK_THROWS_WITH(write_pds3_dem(stretched, path, {}), Catch::Contains("square"));

    auto geographic = dem;
    geographic.crs_wkt = "EPSG:4326";
    CHECK_THROWS_WITH(write_pds3_dem(geographic, path, {}), Catch::Contains("EQUIRECTANGULAR"));

    auto no_crs = dem;
    no_crs.crs_wkt.clear();
    CHECK_THROWS_AS(write_pds3_dem(no_crs, path, {}), terrain::Error);

    auto too_high = dem;
    too_high.values[5] = 255000.0 + 70000.0;  // DN 35000 does not fit an int16
    CHECK_THROWS_WITH(write_pds3_dem(too_high, path, {}),
                      Catch::Contains("column 5, row 0") && Catch::Contains("scaling factor"));
    Pds3DemOptions coarse;
    coarse.scaling_factor = 4.0;
    write_pds3_dem(too_high, path, coarse);  // fits with 4 m per DN
    CHECK(terrain::io::read_dem(path).at(5, 0) == 255000.0 + 70000.0);

    CHECK(listing(dir) == std::vector<std::string>{"x.img", "x.lbl"});
}
