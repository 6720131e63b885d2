// `terrain mesh` and `terrain field` as users run them, outputs read back with GDAL.
#include <cpl_json.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <sstream>

#include "support/test_support.hpp"
#include "terrain/field/sdf.hpp"
#include "terrain/io/mesh_files.hpp"

using Catch::Matchers::Contains;
using terrain::test::run_cli;

namespace {

// The float vertex property `name` of a binary little-endian PLY.
std::vector<float> read_ply_property(const std::string& path, const std::string& name) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    std::size_t vertices = 0, stride = 0, offset = 0;
    bool in_vertex = false, found = false;
    const std::map<std::string, std::size_t> sizes = {
        {"char", 1}, {"uchar", 1}, {"short", 2},  {"ushort", 2}, {"int", 4},
        {"uint", 4}, {"float", 4}, {"double", 8}, {"int32", 4},  {"float32", 4}};
    while (std::getline(in, line) && line != "end_header") {
        std::istringstream words(line);
        std::string word, type, property;
        words >> word;
        if (word == "element") {
            std::size_t count = 0;
            words >> type >> count;
            in_vertex = type == "vertex";
            if (in_vertex) vertices = count;
        } else if (word == "property" && in_vertex) {
            words >> type >> property;
            if (property == name && type == "float") found = true, offset = stride;
            stride += sizes.at(type);
        }
    }
    REQUIRE(found);
    std::vector<char> data(vertices * stride);
    in.read(data.data(), static_cast<std::streamsize>(data.size()));
    REQUIRE(in.gcount() == static_cast<std::streamsize>(data.size()));
    std::vector<float> out(vertices);
    for (std::size_t v = 0; v < vertices; ++v)
        std::memcpy(&out[v], data.data() + v * stride + offset, sizeof(float));
    return out;
}

}  // namespace

TEST_CASE("terrain mesh on the shared DEMs and the samples", "[cli][mesh]") {
    const auto dir = terrain::test::scratch_dir("cli_mesh");
    struct Case {
        std::string input, expect;
    };
    const std::vector<Case> cases = {
        {terrain::test::real_data("moon_lola_ldem4/LDEM_4.LBL").value(),
         "0 boundary edges in 0 loop(s), Euler characteristic 2, frame body"},
        {terrain::test::real_data("earth/bigtujunga_srtm30m_utm11.tif").value(), "frame map"},
        {terrain::test::sample("mars_hirise_crop.tif"), "8400 vertices"},
        {terrain::test::sample("vesta_hamo_tile.lbl"), "262144 vertices"},
        {terrain::test::sample("moon_ldem1_global.tif"), "Euler characteristic 2"},
    };
    int i = 0;
    for (const auto& c : cases) {
        const auto out = (dir / ("m" + std::to_string(i++) + ".ply")).string();
        const auto r = run_cli({"mesh", c.input, "-o", out, "-q"});
        INFO(c.input << ": " << r.err);
        CHECK(r.status == 0);
        CHECK_THAT(r.out, Contains(c.expect));
        CHECK(r.err.empty());  // -q: no progress
    }
    // Existing output refused without --overwrite; progress shown without -q.
    const auto out = (dir / "m0.ply").string();
    const auto again = run_cli({"mesh", terrain::test::sample("mars_hirise_crop.tif"), "-o", out});
    CHECK(again.status == 1);
    CHECK_THAT(again.err, Contains("--overwrite"));
    const auto over =
        run_cli({"mesh", terrain::test::sample("mars_hirise_crop.tif"), "-o", out, "--overwrite"});
    CHECK(over.status == 0);
    CHECK_THAT(over.err, Contains("0...10...20") && Contains("100 - done."));
    CHECK(run_cli({"mesh", terrain::test::sample("mars_hirise_crop.tif"), "-o", out, "--overwrite",
                   "--frame", "body"})
              .status == 1);  // no CRS: no body
    CHECK(run_cli({"mesh", terrain::test::sample("mars_hirise_crop.tif"), "-o",
                   (dir / "no/dir/x.ply").string()})
              .status == 1);
}

TEST_CASE("terrain field writes a Float32 raster on the DEM's exact grid", "[cli][field]") {
    const auto dir = terrain::test::scratch_dir("cli_field");
    // A UTM tile with a NoData hole.
    terrain::test::RasterSpec spec;
    spec.width = 30;
    spec.height = 20;
    spec.crs = "EPSG:32611";
    spec.geotransform = {400000, 30, 0, 3800000, 0, -30};
    spec.nodata = -9999;
    for (int r = 0; r < 20; ++r)
        for (int c = 0; c < 30; ++c)
            spec.values.push_back(c > 12 && c < 16 && r > 8 && r < 12
                                      ? -9999
                                      : 100 * std::sin(c * 0.3) * std::cos(r * 0.2));
    const auto dem = terrain::test::write_raster(dir / "dem.tif", spec);
    const auto out = (dir / "si.tif").string();
    const auto r = run_cli({"field", dem, "--field", "shape-index", "-o", out, "-q"});
    INFO(r.err);
    REQUIRE(r.status == 0);

    GDALAllRegister();
    std::unique_ptr<GDALDataset> ds(GDALDataset::Open(out.c_str(), GDAL_OF_RASTER));
    REQUIRE(ds);
    CHECK(ds->GetRasterXSize() == 30);
    CHECK(ds->GetRasterYSize() == 20);
    double gt[6];
    REQUIRE(ds->GetGeoTransform(gt) == CE_None);
    for (int k = 0; k < 6; ++k) CHECK(gt[k] == spec.geotransform[k]);
    OGRSpatialReference utm;
    utm.SetFromUserInput("EPSG:32611");
    REQUIRE(ds->GetSpatialRef());
    CHECK(ds->GetSpatialRef()->IsSame(&utm));
    GDALRasterBand* band = ds->GetRasterBand(1);
    CHECK(band->GetRasterDataType() == GDT_Float32);
    int has_nodata = 0;
    CHECK(std::isnan(band->GetNoDataValue(&has_nodata)));
    CHECK(has_nodata);
    std::vector<float> values(600);
    REQUIRE(band->RasterIO(GF_Read, 0, 0, 30, 20, values.data(), 30, 20, GDT_Float32, 0, 0) ==
            CE_None);
    std::size_t nan = 0, out_of_range = 0;
    for (float v : values) {
        if (std::isnan(v))
            ++nan;
        else
            out_of_range += v < 0 || v > 100;
    }
    CHECK(nan == 9);  // exactly the DEM's NoData pixels
    CHECK(out_of_range == 0);
    CHECK(std::isnan(values[10 * 30 + 14]));

    // Height: metres above the reference, equal to the DEM's values.
    const auto height = (dir / "h.tif").string();
    REQUIRE(run_cli({"field", dem, "--field", "height", "-o", height, "-q"}).status == 0);
    std::unique_ptr<GDALDataset> h(GDALDataset::Open(height.c_str(), GDAL_OF_RASTER));
    float v = 0;
    REQUIRE(h->GetRasterBand(1)->RasterIO(GF_Read, 5, 3, 1, 1, &v, 1, 1, GDT_Float32, 0, 0) ==
            CE_None);
    CHECK(v == Approx(100 * std::sin(5 * 0.3) * std::cos(3 * 0.2)).margin(1e-3));
}

TEST_CASE("terrain field on a mesh writes a PLY property, bad options are refused",
          "[cli][field]") {
    const auto dir = terrain::test::scratch_dir("cli_field_mesh");
    std::ofstream(dir / "octa.off") << "OFF\n6 8 0\n1 0 0\n-1 0 0\n0 1 0\n0 -1 0\n0 0 1\n0 0 -1\n"
                                       "3 0 2 4\n3 2 1 4\n3 1 3 4\n3 3 0 4\n3 2 0 5\n3 1 2 5\n"
                                       "3 3 1 5\n3 0 3 5\n";
    const auto mesh = (dir / "octa.off").string();
    const auto ply = (dir / "octa.ply").string();
    const auto r = run_cli({"field", mesh, "--field", "height", "-o", ply, "-q"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    std::ifstream in(ply, std::ios::binary);
    std::string header, line;
    while (std::getline(in, line) && line != "end_header") header += line + "\n";
    CHECK_THAT(header, Contains("property float height"));
    CHECK(run_cli({"field", mesh, "--field", "nonsense", "-o", (dir / "n.ply").string()}).status ==
          1);
    CHECK(run_cli({"field", mesh, "-o", (dir / "x.tif").string()}).status == 2);
    CHECK(run_cli({"field", mesh, "-o", (dir / "x.png").string()}).status == 2);
    CHECK(run_cli({"field", mesh, "-o", ply}).status == 1);  // exists
}

TEST_CASE("terrain field --field sdf: a mesh file round trip, open DEM tiles refused",
          "[cli][field][sdf]") {
    const auto dir = terrain::test::scratch_dir("cli_field_sdf");
    // A closed mesh: a box twice as long as it is wide, its long sides cut into squares.
    std::ofstream off(dir / "box.off");
    off << "OFF\n12 20 0\n";
    for (int z = 0; z <= 2; ++z)
        for (const auto& [x, y] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}})
            off << x << " " << y << " " << z << "\n";
    off << "3 0 2 1\n3 0 3 2\n3 8 9 10\n3 8 10 11\n";  // bottom, top
    for (int level = 0; level < 2; ++level)
        for (int k = 0; k < 4; ++k) {
            const int a = 4 * level + k, b = 4 * level + (k + 1) % 4;
            off << "3 " << a << " " << b << " " << b + 4 << "\n3 " << a << " " << b + 4 << " "
                << a + 4 << "\n";
        }
    off.close();
    const auto mesh = (dir / "box.off").string();
    const auto ply = (dir / "box.ply").string();
    const auto r = run_cli({"field", mesh, "--field", "sdf", "--rays", "9", "--cone-angle", "60",
                            "--no-postprocess", "-o", ply, "-q"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK_THAT(r.out, Contains("sdf on 12 vertices, range 0 .. 100"));
    CHECK_THAT(r.out, Contains("vertex diameters"));
    const auto written = read_ply_property(ply, "sdf");
    terrain::field::SdfOptions options;
    options.rays = 9;
    options.cone_angle = std::numbers::pi / 3;
    options.postprocess = false;
    const auto expected =
        terrain::field::shape_diameter_function(terrain::io::read_mesh(mesh), options).values;
    CHECK(written == expected);

    // An open mesh: refused with the count of its boundary edges, or computed when allowed.
    std::ofstream(dir / "open.off") << "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                       "3 0 2 1\n3 0 1 3\n3 0 3 2\n";
    const auto open = (dir / "open.off").string();
    const auto refused = run_cli({"field", open, "--field", "sdf", "-o", ply, "--overwrite"});
    CHECK(refused.status == 1);
    CHECK_THAT(refused.err, Contains("3 boundary edges"));
    CHECK(run_cli({"field", open, "--field", "sdf", "--allow-open", "-o", ply, "--overwrite", "-q"})
              .status == 0);
    // Bad options.
    CHECK(run_cli({"field", mesh, "--field", "sdf", "--rays", "0", "-o", ply, "--overwrite"})
              .status == 1);
    CHECK(
        run_cli({"field", mesh, "--field", "sdf", "--cone-angle", "180", "-o", ply, "--overwrite"})
            .status == 1);
    // The same field options drive the Reeb graph (the paper's part-based case).
    const auto reeb = run_cli(
        {"reeb", mesh, "--field", "sdf", "--rays", "9", "-o", (dir / "box.json").string(), "-q"});
    INFO(reeb.err);
    CHECK(reeb.status == 0);
    // ... and the segmentation, whose run.json records them.
    const auto seg_dir = dir / "box_seg";
    std::filesystem::remove_all(seg_dir);
    const auto seg = run_cli({"segment", mesh, "--field", "sdf", "--rays", "9", "--cone-angle",
                              "60", "--no-postprocess", "-o", seg_dir.string(), "-q"});
    INFO(seg.err);
    REQUIRE(seg.status == 0);
    CPLJSONDocument run;
    REQUIRE(run.Load((seg_dir / "run.json").string()));
    const auto parameters = run.GetRoot().GetObj("parameters");
    CHECK(parameters.GetString("field") == "sdf");
    CHECK(parameters.GetInteger("rays") == 9);
    CHECK(parameters.GetDouble("cone_angle_degrees") == 60);
    CHECK_FALSE(parameters.GetBool("postprocess"));
    CHECK_FALSE(parameters.GetBool("allow_open"));

    // A DEM tile is open: one line saying so. A global DEM closes: its SDF is a raster.
    terrain::test::RasterSpec tile;
    tile.width = tile.height = 10;
    tile.crs = "EPSG:32611";
    tile.geotransform = {400000, 30, 0, 3800000, 0, -30};
    const auto tile_path = terrain::test::write_raster(dir / "tile.tif", tile);
    const auto dem = run_cli(
        {"field", tile_path, "--field", "sdf", "-o", (dir / "tile_sdf.tif").string(), "-q"});
    CHECK(dem.status == 1);
    CHECK_THAT(dem.err, Contains("open surface") && Contains("--field shape-index"));
    terrain::test::RasterSpec global;
    global.width = 36;
    global.height = 18;
    global.crs = "EPSG:4326";
    global.geotransform = {-180, 10, 0, 90, 0, -10};
    for (int row = 0; row < 18; ++row)
        for (int col = 0; col < 36; ++col)
            global.values.push_back(col < 18 ? 0.0 : 1e6);  // one half bulges out
    const auto global_path = terrain::test::write_raster(dir / "global.tif", global);
    const auto out = (dir / "global_sdf.tif").string();
    const auto g = run_cli({"field", global_path, "--field", "sdf", "-o", out, "-q"});
    INFO(g.err);
    REQUIRE(g.status == 0);
    const auto values = terrain::test::read_raster_values(out);
    REQUIRE(values.size() == 36 * 18);
    for (float v : values) {  // every pixel has its vertex (the pole rows collapse)
        CHECK(v >= 0);
        CHECK(v <= 100);
    }
    CHECK(*std::max_element(values.begin(), values.end()) == 100);
}

TEST_CASE("terrain field and segment --window: disk by default with --radius, ball on request",
          "[cli][field]") {
    const auto dir = terrain::test::scratch_dir("cli_window");
    terrain::test::RasterSpec spec;
    spec.width = spec.height = 48;
    spec.crs = "EPSG:32611";
    spec.geotransform = {400000, 30, 0, 3800000, 0, -30};
    for (int r = 0; r < 48; ++r)
        for (int c = 0; c < 48; ++c)
            spec.values.push_back(200 * std::sin(c * 0.21) * std::cos(r * 0.17) + 40 * c);
    const auto dem = terrain::test::write_raster(dir / "dem.tif", spec);
    GDALAllRegister();
    const auto read = [](const std::string& path) {
        std::unique_ptr<GDALDataset> ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
        REQUIRE(ds);
        std::vector<float> values(48 * 48);
        REQUIRE(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, 48, 48, values.data(), 48, 48,
                                               GDT_Float32, 0, 0) == CE_None);
        return values;
    };
    std::map<std::string, std::vector<float>> fields;
    for (const std::string window : {"", "disk", "ball"}) {
        const auto out = (dir / ("si_" + window + ".tif")).string();
        std::vector<std::string> args{"field", dem, "--radius", "150", "-o", out, "-q"};
        if (!window.empty()) args.insert(args.end(), {"--window", window});
        const auto r = run_cli(args);
        INFO(r.err);
        REQUIRE(r.status == 0);
        fields[window] = read(out);
        for (float v : fields[window]) CHECK((v >= 0 && v <= 100));
    }
    CHECK(fields[""] == fields["disk"]);  // the default
    CHECK(fields["disk"] != fields["ball"]);
    // segment records the window it took in run.json.
    for (const std::string window : {"disk", "ball"}) {
        const auto out = (dir / ("seg_" + window)).string();
        const auto r =
            run_cli({"segment", dem, "--radius", "150", "--window", window, "-o", out, "-q"});
        INFO(r.err);
        REQUIRE(r.status == 0);
        CPLJSONDocument run;
        REQUIRE(run.Load(out + "/run.json"));
        CHECK(run.GetRoot().GetString("parameters/shape_index_window") == window);
    }
    const auto bad = run_cli(
        {"field", dem, "--radius", "150", "--window", "cube", "-o", (dir / "bad.tif").string()});
    CHECK(bad.status == 1);
    CHECK_THAT(bad.err, Contains("--window must be disk or ball"));
    CHECK_FALSE(std::filesystem::exists(dir / "bad.tif"));
}
