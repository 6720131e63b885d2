// `terrain sweep`: the scales, their lineage, and agreement with plain `segment` runs.
#include <cpl_json.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>
#include <catch2/catch.hpp>

#include <filesystem>
#include <memory>

#include "support/test_support.hpp"

using Catch::Matchers::Contains;
using terrain::test::run_cli;
namespace fs = std::filesystem;

namespace {

std::vector<std::uint32_t> read_band(const fs::path& path, int band, int* w = nullptr) {
    std::unique_ptr<GDALDataset> ds(
        GDALDataset::FromHandle(GDALOpen(path.string().c_str(), GA_ReadOnly)));
    REQUIRE(ds);
    const int nx = ds->GetRasterXSize(), ny = ds->GetRasterYSize();
    if (w) *w = nx;
    std::vector<std::uint32_t> px(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny));
    REQUIRE(ds->GetRasterBand(band)->RasterIO(GF_Read, 0, 0, nx, ny, px.data(), nx, ny, GDT_UInt32,
                                              0, 0) == CE_None);
    return px;
}

}  // namespace

TEST_CASE("terrain sweep: scales agree with segment, counts fall, lineage adds up",
          "[cli][sweep]") {
    GDALAllRegister();
    const auto dir = terrain::test::scratch_dir("cli_sweep");
    const auto dem = terrain::test::sample("vesta_hamo_tile.lbl");
    const auto out = dir / "sweep";
    auto r = run_cli({"sweep", dem, "-o", out.string(), "-q", "--area-ratios", "2,0.1,0.5,1,0.25"});
    INFO(r.err);
    REQUIRE(r.status == 0);
    for (const char* name :
         {"labels.tif", "regions.gpkg", "regions_0.1.geojson", "regions_2.geojson",
          "adjacency_0.5.json", "lineage.json", "sweep.csv", "sweep.png", "run.json"})
        CHECK(fs::exists(out / name));
    // Bands in increasing area ratio, described; region counts never increase.
    std::unique_ptr<GDALDataset> labels(
        GDALDataset::FromHandle(GDALOpen((out / "labels.tif").string().c_str(), GA_ReadOnly)));
    REQUIRE(labels);
    REQUIRE(labels->GetRasterCount() == 5);
    CHECK(std::string(labels->GetRasterBand(1)->GetDescription()) == "area_ratio=0.1");
    CHECK(std::string(labels->GetRasterBand(3)->GetDescription()) == "area_ratio=0.5");
    std::uint32_t last = UINT32_MAX;
    for (int b = 1; b <= 5; ++b) {
        const auto px = read_band(out / "labels.tif", b);
        const auto count = *std::max_element(px.begin(), px.end());
        CHECK(count <= last);
        last = count;
    }
    // The finest scale (0.1 %) is byte for byte the labels of a plain segment run at 0.1 %
    // (the coarser ones continue from it).
    const auto seg = dir / "seg";
    REQUIRE(run_cli({"segment", dem, "-o", seg.string(), "-q", "--area-ratio", "0.1"}).status == 0);
    CHECK(read_band(out / "labels.tif", 1) == read_band(seg / "labels.tif", 1));
    // Lineage: every region overlaps the next scale, and its overlaps add up to its area.
    CPLJSONDocument lineage;
    REQUIRE(lineage.Load((out / "lineage.json").string()));
    const auto links = lineage.GetRoot().GetArray("links");
    REQUIRE(links.Size() == 4);
    for (int i = 0; i < links.Size(); ++i) {
        const auto regions = links[i].GetArray("regions");
        CHECK(regions.Size() > 0);
        CHECK(links[i].GetDouble("mean_parent_share") > 0.85);  // 0.87-1.0 on this tile
        for (int k = 0; k < regions.Size(); ++k) {
            const auto overlaps = regions[k].GetArray("overlaps");
            REQUIRE(overlaps.Size() >= 1);
            double area = 0, fraction = 0;
            for (int o = 0; o < overlaps.Size(); ++o) {
                area += overlaps[o].GetDouble("area_m2");
                fraction += overlaps[o].GetDouble("fraction");
            }
            CHECK(area == Approx(regions[k].GetDouble("area_m2")).epsilon(1e-9));
            CHECK(fraction == Approx(1.0).epsilon(1e-9));
            // Its parent is its largest overlap, with that share.
            double largest = 0;
            int parent = 0;
            for (int o = 0; o < overlaps.Size(); ++o)
                if (overlaps[o].GetDouble("fraction") > largest) {
                    largest = overlaps[o].GetDouble("fraction");
                    parent = overlaps[o].GetInteger("region");
                }
            CHECK(regions[k].GetInteger("parent") == parent);
            CHECK(regions[k].GetDouble("parent_share") == largest);
        }
    }
    // The GeoPackage has one layer per scale, and layer_styles with two styles for each.
    std::unique_ptr<GDALDataset> gpkg(GDALDataset::FromHandle(GDALOpenEx(
        (out / "regions.gpkg").string().c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr)));
    REQUIRE(gpkg);
    CHECK(gpkg->GetLayerCount() == 6);
    CHECK(gpkg->GetLayerByName("regions_0.25") != nullptr);
    OGRLayer* styles = gpkg->GetLayerByName("layer_styles");
    REQUIRE(styles);
    CHECK(styles->GetFeatureCount() == 10);  // by region (the default) and by landform
    // Bad scales: one line, status 1; --area-ratio is not the sweep's option.
    r = run_cli({"sweep", dem, "-o", (dir / "bad").string(), "-q", "--area-ratios", "0.1,abc"});
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Contains("'abc'"));
    CHECK(run_cli({"sweep", dem, "-o", (dir / "bad").string(), "-q", "--area-ratio", "1"}).status ==
          2);
    CHECK_FALSE(fs::exists(dir / "bad"));
}
