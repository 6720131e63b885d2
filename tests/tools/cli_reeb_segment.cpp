// `terrain reeb` and `terrain segment` as users run them; outputs read back with GDAL/OGR.
#include <cpl_json.h>
#include <gdal_priv.h>
#include <gdal_utils.h>
#include <ogrsf_frmts.h>
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "support/test_support.hpp"
#include "terrain/core/huge_pages.hpp"

using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;
using terrain::test::run_cli;
namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

// A 64x64 crop of the Vesta sample as GeoTIFF (keeps the CLI tests quick).
std::string vesta_crop(const fs::path& dir) {
    const auto out = (dir / "vesta_crop.tif").string();
    if (fs::exists(out)) return out;
    GDALAllRegister();
    std::unique_ptr<GDALDataset> src(GDALDataset::FromHandle(
        GDALOpen(terrain::test::sample("vesta_hamo_tile.lbl").c_str(), GA_ReadOnly)));
    REQUIRE(src);
    const char* args[] = {"-srcwin", "100", "100", "64", "64", nullptr};
    auto* options = GDALTranslateOptionsNew(const_cast<char**>(args), nullptr);
    GDALClose(GDALTranslate(out.c_str(), src.get(), options, nullptr));
    GDALTranslateOptionsFree(options);
    return out;
}

}  // namespace

TEST_CASE("terrain reeb writes the graph as JSON and DOT", "[cli][reeb]") {
    const auto dir = terrain::test::scratch_dir("cli_reeb");
    const auto dem = vesta_crop(dir);
    const auto json = (dir / "g.json").string();
    auto r = run_cli({"reeb", dem, "-o", json, "-q", "--persistence", "10", "--area-ratio", "0.5",
                      "--write-field", (dir / "f.tif").string()});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CPLJSONDocument doc;
    REQUIRE(doc.Load(json));
    const auto root = doc.GetRoot();
    const auto nodes = root.GetArray("nodes");
    const auto arcs = root.GetArray("arcs");
    CHECK(nodes.Size() > 1);
    CHECK(arcs.Size() == nodes.Size() - 1);  // a tree on a disk
    CHECK(root.GetObj("mesh").GetLong("vertices") == 64 * 64);
    CHECK(root.GetObj("mesh").GetLong("euler_characteristic") == 1);
    CHECK(root.GetObj("summary").GetLong("loops") == 0);
    for (int i = 0; i < arcs.Size(); ++i) {
        const auto a = arcs[i];
        const auto from = nodes[a.GetInteger("from")], to = nodes[a.GetInteger("to")];
        CHECK(from.GetDouble("value") <= to.GetDouble("value"));
    }
    const std::string type = nodes[0].GetString("type");
    CHECK((type == "min" || type == "max" || type == "saddle"));
    // The simplified field: a raster on the DEM's grid.
    std::unique_ptr<GDALDataset> f(
        GDALDataset::FromHandle(GDALOpen((dir / "f.tif").string().c_str(), GA_ReadOnly)));
    REQUIRE(f);
    CHECK(f->GetRasterXSize() == 64);
    // DOT, existing output, bad thresholds, bad extension.
    const auto dot = (dir / "g.dot").string();
    CHECK(run_cli({"reeb", dem, "-o", dot, "-q"}).status == 0);
    CHECK_THAT(slurp(dot), Contains("graph reeb {"));
    r = run_cli({"reeb", dem, "-o", json, "-q"});
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Contains("--overwrite"));
    r = run_cli({"reeb", dem, "-o", json, "-q", "--overwrite", "--area-ratio", "150"});
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Contains("percent"));
    CHECK(run_cli({"reeb", dem, "-o", (dir / "g.txt").string(), "-q"}).status == 2);
    // A failure after progress started is reported on a line of its own.
    r = run_cli({"field", dem, "--field", "sdf", "-o", (dir / "sdf.tif").string()});
    CHECK(r.status == 1);
    CHECK_THAT(r.err, StartsWith("0...10...") && Contains("\nterrain field: sdf: "));
}

TEST_CASE("terrain segment writes every output, complete or not at all", "[cli][segment]") {
    const auto dir = terrain::test::scratch_dir("cli_segment");
    const auto dem = vesta_crop(dir);
    const auto out = dir / "seg";
    auto r = run_cli({"segment", dem, "-o", out.string(), "-q", "--timings"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK_THAT(r.out, Contains("regions on 4096 vertices") && Contains("simplify"));
    for (const char* name : {"labels.tif", "regions.geojson", "adjacency.json", "adjacency.graphml",
                             "adjacency.geojson", "preview.png", "run.json"})
        CHECK(fs::exists(out / name));
    CPLJSONDocument run;
    REQUIRE(run.Load((out / "run.json").string()));
    const auto counts = run.GetRoot().GetObj("counts");
    const long regions = counts.GetLong("regions");
    CHECK(counts.GetLong("vertices") == 4096);
    CHECK(counts.GetLong("faces") == 2 * 63 * 63);
    CHECK(counts.GetLong("boundary_edges") == 4 * 63);   // the square's rim
    CHECK(counts.GetLong("euler_characteristic") == 1);  // a disk
    CHECK(regions >= 1);
    CHECK(run.GetRoot().GetObj("parameters").GetString("cost") == "graph");
    CHECK(run.GetRoot().GetObj("timings_seconds").GetDouble("reeb") >= 0);
    // Labels cover every pixel with 1..regions; the polygons are one valid feature per region.
    std::unique_ptr<GDALDataset> labels(
        GDALDataset::FromHandle(GDALOpen((out / "labels.tif").string().c_str(), GA_ReadOnly)));
    REQUIRE(labels);
    std::vector<std::uint32_t> px(64 * 64);
    REQUIRE(labels->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, 64, 64, px.data(), 64, 64, GDT_UInt32,
                                               0, 0) == CE_None);
    CHECK(*std::min_element(px.begin(), px.end()) == 1);
    CHECK(*std::max_element(px.begin(), px.end()) == static_cast<std::uint32_t>(regions));
    std::unique_ptr<GDALDataset> vec(GDALDataset::FromHandle(GDALOpenEx(
        (out / "regions.geojson").string().c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr)));
    REQUIRE(vec);
    CHECK(vec->GetLayer(0)->GetFeatureCount() == regions);
    // Same input, same bytes (run.json holds timings and is the exception).
    const auto again = dir / "seg2";
    REQUIRE(run_cli({"segment", dem, "-o", again.string(), "-q"}).status == 0);
    for (const char* name : {"labels.tif", "regions.geojson", "adjacency.json", "preview.png"})
        CHECK(slurp(out / name) == slurp(again / name));
    // An existing directory is refused without --overwrite and left as it was.
    r = run_cli({"segment", dem, "-o", out.string(), "-q", "--persistence", "50"});
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Contains("already exists; pass --overwrite"));
    CHECK(slurp(out / "labels.tif") == slurp(again / "labels.tif"));
    // Thresholds out of range: one line, status 1, nothing written.
    const auto bad = dir / "bad";
    r = run_cli({"segment", dem, "-o", bad.string(), "-q", "--area-ratio", "-1"});
    CHECK(r.status == 1);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK_FALSE(fs::exists(bad));
    r = run_cli({"segment", dem, "-o", bad.string(), "-q", "--cost", "cheapest"});
    CHECK(r.status == 1);
    CHECK_FALSE(fs::exists(bad));
    CHECK(run_cli({"segment", dem, "-o", (dir / "no" / "such" / "dir").string(), "-q"}).status ==
          1);
    // --overwrite replaces the directory; a huge persistence leaves few regions.
    r = run_cli({"segment", dem, "-o", out.string(), "-q", "--overwrite", "--persistence", "100"});
    CHECK(r.status == 0);
    CPLJSONDocument run2;
    REQUIRE(run2.Load((out / "run.json").string()));
    CHECK(run2.GetRoot().GetObj("counts").GetLong("regions") <= regions);
    // No temporary directories left behind.
    for (const auto& e : fs::directory_iterator(dir))
        CHECK(e.path().filename().string().find(".tmp") == std::string::npos);
}

TEST_CASE("terrain segment asks for huge pages when the kernel gives them on request",
          "[cli][segment]") {
    const auto dir = terrain::test::scratch_dir("cli_huge_pages");
    const auto dem = vesta_crop(dir);
    const auto mode = terrain::transparent_huge_page_mode();
    const auto pages = [](const fs::path& out) {
        CPLJSONDocument run;
        REQUIRE(run.Load((out / "run.json").string()));
        return run.GetRoot().GetString("pages");
    };
    // Started again with the tunable: its arguments (a space in a path) reach it unchanged.
    const auto asked = dir / "huge pages";
    fs::remove_all(asked);
    auto r = run_cli({"segment", dem, "-o", asked.string(), "-q"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(pages(asked) == (mode == "always" || mode == "madvise" ? "huge" : "normal"));
    // TERRAIN_HUGE_PAGES=0, or the caller's own tunable, keep the pages normal (unless the
    // kernel makes every large mapping huge).
    const std::string kept = mode == "always" ? "huge" : "normal";
    for (const auto& [name, setting] :
         {std::pair<const char*, const char*>{"normal", "TERRAIN_HUGE_PAGES=0"},
          {"own", "GLIBC_TUNABLES=glibc.malloc.hugetlb=0"}}) {
        INFO(setting);
        const auto out = dir / name;
        fs::remove_all(out);
        r = terrain::test::run_program(TERRAIN_CLI, {"segment", dem, "-o", out.string(), "-q"},
                                       {setting});
        REQUIRE(r.status == 0);
        CHECK(pages(out) == kept);
        // The same outputs, byte for byte.
        for (const char* file : {"labels.tif", "regions.geojson", "adjacency.json", "preview.png"})
            CHECK(slurp(asked / file) == slurp(out / file));
    }
}

TEST_CASE("terrain segment keeps its large blocks for reuse with the same outputs",
          "[cli][segment]") {
    // The whole 512 x 512 tile: its per-vertex positions (6 MiB) and several other arrays
    // are large blocks, freed and taken again from stage to stage.
    const auto dir = terrain::test::scratch_dir("cli_large_blocks");
    const auto dem = terrain::test::sample("vesta_hamo_tile.lbl");
    const auto kept = dir / "kept";
    const auto malloced = dir / "malloc";
    fs::remove_all(kept);
    fs::remove_all(malloced);
    auto r = run_cli({"segment", dem, "-o", kept.string(), "-q"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    r = terrain::test::run_program(TERRAIN_CLI, {"segment", dem, "-o", malloced.string(), "-q"},
                                   {"TERRAIN_LARGE_BLOCKS=0"});
    REQUIRE(r.status == 0);
    for (const char* file : {"labels.tif", "regions.geojson", "adjacency.json", "preview.png"})
        CHECK(slurp(kept / file) == slurp(malloced / file));
}

TEST_CASE("terrain segment on a constant field, a mostly-NoData DEM and a mesh file",
          "[cli][segment]") {
    const auto dir = terrain::test::scratch_dir("cli_segment_edge");
    terrain::test::RasterSpec flat;
    flat.width = flat.height = 20;
    flat.values.assign(400, 5.0);
    const auto flat_tif = terrain::test::write_raster(dir / "flat.tif", flat);
    auto r =
        run_cli({"segment", flat_tif, "-o", (dir / "flat").string(), "-q", "--field", "height"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK_THAT(r.out, Contains("1 regions"));
    // 90% NoData: a small valid island still segments.
    terrain::test::RasterSpec holes;
    holes.width = holes.height = 40;
    holes.nodata = -9999;
    for (int row = 0; row < 40; ++row)
        for (int col = 0; col < 40; ++col)
            holes.values.push_back((row >= 10 && row < 22 && col >= 10 && col < 22)
                                       ? std::sin(col * 0.7) * std::cos(row * 0.5) * 20
                                       : -9999);
    const auto holes_tif = terrain::test::write_raster(dir / "holes.tif", holes);
    r = run_cli({"segment", holes_tif, "-o", (dir / "holes").string(), "-q"});
    CHECK(r.status == 0);
    std::unique_ptr<GDALDataset> labels(GDALDataset::FromHandle(
        GDALOpen((dir / "holes" / "labels.tif").string().c_str(), GA_ReadOnly)));
    REQUIRE(labels);
    std::vector<std::uint32_t> px(1600);
    REQUIRE(labels->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, 40, 40, px.data(), 40, 40, GDT_UInt32,
                                               0, 0) == CE_None);
    for (int i = 0; i < 1600; ++i) {
        const bool valid = holes.values[static_cast<std::size_t>(i)] != -9999;
        CHECK((px[static_cast<std::size_t>(i)] != 0) == valid);
    }
    // A mesh file: labels.ply and faces.seg, one label per face.
    const auto mesh = dir / "tetra_box.off";
    {
        std::ofstream off(mesh);
        off << "OFF\n8 12 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
               "3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n"
               "3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n";
    }
    r = run_cli({"segment", mesh.string(), "-o", (dir / "box").string(), "-q", "--field", "height",
                 "--persistence", "0", "--area-ratio", "0"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(fs::exists(dir / "box" / "labels.ply"));
    const auto seg = slurp(dir / "box" / "faces.seg");
    CHECK(std::count(seg.begin(), seg.end(), '\n') == 12);
    CHECK_FALSE(fs::exists(dir / "box" / "labels.tif"));
}

TEST_CASE("The figures are written by the program alone, wherever it lies", "[cli][segment]") {
    const auto dir = terrain::test::scratch_dir("cli_image_files");
    const auto dem = vesta_crop(dir);
    // The program away from the build tree writes its PNG figures (GDAL's PNG driver, text by
    // FreeType): nothing is looked for beside it.
    const auto bin = dir / "moved" / "bin";
    fs::create_directories(bin);
    const auto program = bin / "terrain";
    fs::copy_file(TERRAIN_CLI, program, fs::copy_options::overwrite_existing);
    const auto out = dir / "seg";
    fs::remove_all(out);
    auto r =
        terrain::test::run_program(program.string(), {"segment", dem, "-o", out.string(), "-q"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    for (const auto& [name, bands] : {std::pair{"preview.png", 4}, std::pair{"craters.png", 3}}) {
        INFO(name);
        const auto path = (out / name).string();
        GDALDatasetUniquePtr png(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
        REQUIRE(png);
        CHECK(std::string(png->GetDriver()->GetDescription()) == "PNG");
        CHECK(png->GetRasterCount() == bands);
        CHECK(png->GetRasterXSize() > 100);
        // No side file beside the figure.
        CHECK_FALSE(fs::exists(path + ".aux.xml"));
    }
}
