#include <catch2/catch.hpp>

#include "support/segment_support.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/io/write_segment_outputs.hpp"

using namespace terrain;

TEST_CASE("write_segment_outputs writes a DEM's files, or none when one exists",
          "[write_segment_outputs]") {
    const Dem moon =
        test::crop(io::read_dem(test::sample("moon_ldem4_copernicus.tif")), 0, 0, 40, 30);
    const auto t = test::segment_tile(moon, test::voronoi_cells(moon, 3, 3));
    const io::SegmentOutputOptions defaults;
    const auto dir = test::scratch_dir("write_segment_outputs");
    const auto paths = io::write_segment_outputs(dir.string(), t.mesh, t.field, t.labels, t.graph,
                                                 &t.dem, defaults);
    std::vector<std::string> names;
    for (const auto& p : paths) names.push_back(std::filesystem::path(p).filename().string());
    CHECK(names == std::vector<std::string>{"labels.tif", "regions.geojson", "adjacency.json",
                                            "adjacency.graphml", "adjacency.geojson",
                                            "preview.png"});
    for (const auto& p : paths) CHECK(std::filesystem::file_size(p) > 0);
    CHECK(std::filesystem::exists(dir / "labels.tif.aux.xml"));

    // One existing file: nothing is written, not even the missing ones.
    std::filesystem::remove(dir / "preview.png");
    CHECK_THROWS_AS(io::write_segment_outputs(dir.string(), t.mesh, t.field, t.labels, t.graph,
                                              &t.dem, defaults),
                    Error);
    CHECK_FALSE(std::filesystem::exists(dir / "preview.png"));
    io::SegmentOutputOptions options;
    options.overwrite = true;
    options.polygons.driver = "GPKG";
    const auto again = io::write_segment_outputs(dir.string(), t.mesh, t.field, t.labels, t.graph,
                                                 &t.dem, options);
    CHECK(std::filesystem::path(again[1]).filename() == "regions.gpkg");
    CHECK(std::filesystem::exists(dir / "preview.png"));
    CHECK_THROWS_AS(io::write_segment_outputs((dir / "missing").string(), t.mesh, t.field, t.labels,
                                              t.graph, &t.dem, defaults),
                    Error);
}

TEST_CASE("write_segment_outputs for a mesh file: PLY, faces.seg and the graphs",
          "[write_segment_outputs]") {
    const Dem mars = io::read_dem(test::sample("mars_hirise_crop.tif"));
    auto t = test::segment_tile(mars, test::voronoi_cells(mars, 2, 2));
    t.graph = segment::region_graph(t.mesh, t.field, t.labels, t.region_count, nullptr);
    const io::SegmentOutputOptions defaults;
    const auto dir = test::scratch_dir("write_segment_outputs_mesh");
    const auto paths = io::write_segment_outputs(dir.string(), t.mesh, t.field, t.labels, t.graph,
                                                 nullptr, defaults);
    std::vector<std::string> names;
    for (const auto& p : paths) names.push_back(std::filesystem::path(p).filename().string());
    CHECK(names == std::vector<std::string>{"labels.ply", "faces.seg", "adjacency.json",
                                            "adjacency.graphml", "adjacency.geojson"});
    for (const auto& p : paths) CHECK(std::filesystem::file_size(p) > 0);
}
