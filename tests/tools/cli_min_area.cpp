// --min-area and --min-areas on the command line: exit statuses, what run.json and the Reeb
// JSON record, and the equivalence with --area-ratio.
#include <cpl_json.h>
#include <gdal_priv.h>
#include <catch2/catch.hpp>

#include <filesystem>
#include <memory>

#include "support/test_support.hpp"

using Catch::Matchers::Contains;
using terrain::test::run_cli;
namespace fs = std::filesystem;

namespace {

CPLJSONObject load_json(const fs::path& path) {
    CPLJSONDocument doc;
    REQUIRE(doc.Load(path.string()));
    return doc.GetRoot();
}

}  // namespace

TEST_CASE("terrain segment, reeb and sweep refuse bad areas (1) and two thresholds (2)",
          "[cli][min-area]") {
    const auto dir = terrain::test::scratch_dir("cli_min_area_errors");
    const auto dem = terrain::test::sample("moon_ldem4_copernicus.tif");
    const auto out = (dir / "out").string();
    auto r = run_cli({"segment", dem, "-o", out, "-q", "--min-area", "5 furlongs"});
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Contains("--min-area") && Contains("5 furlongs"));
    CHECK(run_cli({"segment", dem, "-o", out, "-q", "--min-area", "-5km2"}).status == 1);
    r = run_cli({"segment", dem, "-o", out, "-q", "--min-area", "5km2", "--area-ratio", "0.5"});
    CHECK(r.status == 2);
    CHECK_THAT(r.err, Contains("not both"));
    CHECK(run_cli({"reeb", dem, "-o", (dir / "g.json").string(), "-q", "--min-area", "x"}).status ==
          1);
    CHECK(run_cli({"reeb", dem, "-o", (dir / "g.json").string(), "-q", "--min-area", "5km2",
                   "--area-ratio", "1"})
              .status == 2);
    CHECK(run_cli({"sweep", dem, "-o", out, "-q", "--min-areas", "1km2,abc"}).status == 1);
    CHECK(run_cli({"sweep", dem, "-o", out, "-q", "--min-areas", "1km2", "--area-ratios", "1,2"})
              .status == 2);
    CHECK(run_cli({"sweep", dem, "-o", out, "-q", "--min-area", "1km2"}).status == 2);
    CHECK_FALSE(fs::exists(out));
}

TEST_CASE("terrain reeb --min-area gives the graph of --area-ratio 100 X / A", "[cli][min-area]") {
    const auto dir = terrain::test::scratch_dir("cli_min_area_reeb");
    const auto dem = terrain::test::sample("moon_ldem4_copernicus.tif");
    const auto a = dir / "area.json", b = dir / "ratio.json";
    auto r = run_cli({"reeb", dem, "-o", a.string(), "-q", "--overwrite", "--min-area", "150km2"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    const auto by_area = load_json(a);
    const auto params = by_area.GetObj("parameters");
    CHECK(params.GetString("min_area") == "150km2");
    CHECK(params.GetDouble("min_area_m2") == 1.5e8);
    const double ratio = params.GetDouble("area_ratio_percent");
    CHECK(ratio > 0);
    CHECK(ratio < 100);
    // The ratio as recorded (shortest round-trip text), given back as --area-ratio.
    r = run_cli({"reeb", dem, "-o", b.string(), "-q", "--overwrite", "--area-ratio",
                 params["area_ratio_percent"].ToString()});
    REQUIRE(r.status == 0);
    const auto by_ratio = load_json(b);
    CHECK(by_area.GetArray("nodes").ToString() == by_ratio.GetArray("nodes").ToString());
    CHECK(by_area.GetArray("arcs").ToString() == by_ratio.GetArray("arcs").ToString());
    CHECK(by_area.GetObj("summary").ToString() == by_ratio.GetObj("summary").ToString());
}

TEST_CASE("terrain segment and sweep --min-area(s): run.json, bands, same labels",
          "[cli][min-area][sweep]") {
    GDALAllRegister();
    const auto dir = terrain::test::scratch_dir("cli_min_area_segment");
    const auto dem = terrain::test::sample("moon_ldem4_copernicus.tif");
    const auto seg = dir / "seg", sweep = dir / "sweep";
    auto r =
        run_cli({"segment", dem, "-o", seg.string(), "-q", "--overwrite", "--min-area", "20000ha"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    const auto params = load_json(seg / "run.json").GetObj("parameters");
    CHECK(params.GetString("min_area") == "20000ha");
    CHECK(params.GetDouble("min_area_m2") == 2e8);
    const double ratio = params.GetDouble("area_ratio_percent");
    CHECK(ratio > 0);
    CHECK(ratio != 0.5);

    r = run_cli(
        {"sweep", dem, "-o", sweep.string(), "-q", "--overwrite", "--min-areas", "200km2,50km2"});
    REQUIRE(r.status == 0);
    CHECK_THAT(r.out, Contains("50km2:") && Contains("200km2:"));
    CHECK(fs::exists(sweep / "regions_50km2.geojson"));
    CHECK(fs::exists(sweep / "adjacency_200km2.json"));
    std::unique_ptr<GDALDataset> bands(
        GDALDataset::FromHandle(GDALOpen((sweep / "labels.tif").string().c_str(), GA_ReadOnly)));
    REQUIRE(bands);
    REQUIRE(bands->GetRasterCount() == 2);
    CHECK(std::string(bands->GetRasterBand(2)->GetDescription()) == "min_area=200km2");
    std::unique_ptr<GDALDataset> one(
        GDALDataset::FromHandle(GDALOpen((seg / "labels.tif").string().c_str(), GA_ReadOnly)));
    REQUIRE(one);
    const int w = one->GetRasterXSize(), h = one->GetRasterYSize();
    std::vector<std::uint32_t> p(static_cast<std::size_t>(w) * h), q(p.size());
    REQUIRE(one->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, w, h, p.data(), w, h, GDT_UInt32, 0,
                                            0) == CE_None);
    // The finest scale (50 km^2) is a plain segment at that area; the coarser one continues
    // from its graph, so it is not the plain segment at 200 km^2 (= 20000 ha).
    const auto fine = dir / "seg50";
    REQUIRE(
        run_cli({"segment", dem, "-o", fine.string(), "-q", "--overwrite", "--min-area", "50km2"})
            .status == 0);
    std::unique_ptr<GDALDataset> one50(
        GDALDataset::FromHandle(GDALOpen((fine / "labels.tif").string().c_str(), GA_ReadOnly)));
    REQUIRE(one50);
    REQUIRE(one50->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, w, h, p.data(), w, h, GDT_UInt32, 0,
                                              0) == CE_None);
    REQUIRE(bands->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, w, h, q.data(), w, h, GDT_UInt32, 0,
                                              0) == CE_None);
    CHECK(p == q);
    const auto run = load_json(sweep / "run.json");
    CHECK(run.GetArray("scales")[0].GetDouble("min_area_m2") == 5e7);
    CHECK(run.GetArray("scales")[1].GetDouble("area_ratio_percent") == ratio);
    const auto lineage = load_json(sweep / "lineage.json");
    CHECK(lineage.GetArray("min_areas_m2").Size() == 2);
}
