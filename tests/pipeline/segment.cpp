// pipeline::segment and pipeline::sweep: the library calls behind `terrain segment` and
// `terrain sweep`, their values and the directory they write.
#include <catch2/catch.hpp>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>
#include <tuple>

#include "support/test_meshes.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/pipeline/segment.hpp"
#include "terrain/pipeline/sweep.hpp"
#include "terrain/reeb/reeb_graph.hpp"
#include "terrain/reeb/simplify.hpp"
#include "terrain/segment/lineage.hpp"

namespace fs = std::filesystem;
using namespace terrain;

TEST_CASE("pipeline::segment gives labels, regions and the files of terrain segment",
          "[pipeline]") {
    const std::string path = test::sample("moon_ldem4_copernicus.tif");
    pipeline::SegmentOptions options;
    double last = -1;
    bool monotone = true;
    std::set<std::string> reported;
    auto result =
        pipeline::segment(pipeline::load_input(path), options, [&](double f, std::string_view m) {
            monotone = monotone && f >= last - 1e-12;
            last = f;
            reported.insert(std::string(m));
            return true;
        });
    CHECK(monotone);
    CHECK(last == Approx(1.0));
    // Every long stage reports, the division of absorbed vertices and the region graph too
    // (on a global grid of 66 M pixels each takes a minute).
    for (const char* stage : {"shape index", "simplify", "divide", "regions"}) {
        INFO(stage);
        CHECK(reported.count(stage) == 1);
    }
    REQUIRE(result.dem());
    const auto n = result.segmentation.region_count;
    REQUIRE(n > 1);
    CHECK(result.regions.regions.size() == n);
    CHECK(result.segmentation.labels.size() == result.input.mesh.vertex_count());
    const auto pixels = result.label_pixels();
    REQUIRE(pixels.size() == result.dem()->values.size());
    std::set<std::uint32_t> used(pixels.begin(), pixels.end());
    used.erase(0);
    CHECK(used.size() == n);
    CHECK(*used.rbegin() == n);
    std::vector<std::string> stages;
    for (const auto& t : result.timings) stages.push_back(t.name);
    CHECK(stages == std::vector<std::string>{"read", "mesh", "field", "reeb", "simplify", "grow"});
    // The positions, freed while the Reeb graph and the simplification ran, are back: the
    // same floats as those of the mesh made of the DEM.
    CHECK_FALSE(result.input.mesh.positions_released());
    CHECK(result.input.mesh.positions() == mesh::dem_to_mesh(*result.dem()).positions());
    // The critical nodes before the simplification, counted from the node kinds: those of the
    // graph's summary.
    CHECK(result.critical_before ==
          reeb::summarize(reeb::build_reeb_graph(result.input.mesh, result.field)).critical);
    CHECK(result.critical_before > result.after.critical);

    // The directory: labels.tif holds label_pixels(); run.json is listed last.
    const auto dir = test::scratch_dir("pipeline_segment");
    const auto files = pipeline::write_segment_directory(result, options, path, dir.string());
    CHECK(files.front() == "labels.tif");
    CHECK(files[1] == "labels.qml");
    CHECK(files.back() == "run.json");
    for (const auto& f : files) CHECK(fs::exists(dir / f));
    const auto written = test::read_raster_values((dir / "labels.tif").string());
    REQUIRE(written.size() == pixels.size());
    CHECK(std::equal(pixels.begin(), pixels.end(), written.begin(),
                     [](std::uint32_t a, float b) { return static_cast<float>(a) == b; }));

    // The same DEM handed over in memory gives the same labels.
    auto again = pipeline::segment(pipeline::input_from_dem(io::read_dem(path)), options);
    CHECK(again.label_pixels() == pixels);

    // Written as `terrain segment` writes (the large data freed as soon as no file needs it:
    // the mesh's geometry before the files, the rest before the preview is encoded): the
    // same bytes in every file, and the same counts in run.json.
    pipeline::WriteOptions freeing;
    freeing.release_memory = true;
    const auto dir2 = test::scratch_dir("pipeline_segment_freeing");
    CHECK(pipeline::write_segment_directory(again, options, path, dir2.string(), freeing) == files);
    CHECK((again.input.mesh.positions_released() || again.input.mesh.positions().empty()));
    CHECK(again.input.mesh.vertex_areas.empty());
    const auto counts = [](const std::string& json) {
        const auto at = json.find("\"counts\"");
        return at == std::string::npos ? std::string() : json.substr(at, json.find('}', at) - at);
    };
    for (const auto& f : files) {
        INFO(f);
        const auto a = test::file_bytes(dir / f), b = test::file_bytes(dir2 / f);
        if (f == "run.json") {
            CHECK_FALSE(counts(a).empty());
            CHECK(counts(a) == counts(b));
        } else {
            CHECK(a == b);
        }
    }
}

TEST_CASE("pipeline::segment gives the DEM back bit for bit, floats or not", "[pipeline]") {
    // The values are held as floats while the Reeb graph and the simplification run when
    // every one is a float (the first DEM), and stay doubles otherwise (the second: tenths of
    // a metre on a Moon radius); either way the growing and the outputs see the same numbers.
    // With a hole (a Reeb graph with a loop) and without (a tree: the field is parked once the
    // Reeb graph's events are ordered).
    // The height field reads the DEM: it is parked after it.
    for (const auto& [step, hole, field] : {std::tuple{0.5, true, "shape-index"},
                                            {0.1, true, "shape-index"},
                                            {0.5, false, "shape-index"},
                                            {0.5, false, "height"},
                                            {0.1, true, "height"}}) {
        INFO("step " << step << (hole ? ", a hole, " : ", no hole, ") << field);
        const Dem dem = test::grid_dem(90, 70, [&](int c, int r) {
            if (hole && (c - 30) * (c - 30) + (r - 20) * (r - 20) < 40) return std::nan("");
            return 1737400.0 + step * std::round(40 * std::sin(c * 0.2) * std::cos(r * 0.15) +
                                                 ((c * 7919 + r * 104729) % 13));
        });
        // Parked on disk (every array, whatever its size) or held in memory: the same.
        pipeline::SegmentOptions parking, holding;
        parking.park_min_bytes = 0;
        parking.park_directory = test::scratch_dir("pipeline_parked").string();
        holding.park_min_bytes = SIZE_MAX;
        parking.field = holding.field = field::parse_field_kind(field);
        const auto result =
            pipeline::segment(pipeline::input_from_dem(dem, MeshFrame::map), parking);
        REQUIRE(result.dem());
        const auto& back = result.dem()->values;
        REQUIRE(back.size() == dem.values.size());
        CHECK(std::memcmp(back.data(), dem.values.data(), back.size() * sizeof(double)) == 0);
        CHECK(result.segmentation.region_count > 1);
        // Parked at the simplification's peak: the DEM's values (as floats when they all
        // are), the field, the pixel maps, the directions, the vertices' areas, the Reeb
        // graph's vertices' nodes, and the simplification's new numbers of its nodes.
        const std::size_t n = dem.values.size(), nv = result.input.mesh.vertex_count();
        const std::size_t dem_bytes = (step == 0.5 ? 4 : 8) * n;
        pipeline::SegmentResult unsimplified;
        unsimplified.input = pipeline::input_from_dem(dem, MeshFrame::map);
        pipeline::compute_field(unsimplified, holding);
        const std::size_t nodes = pipeline::compute_reeb(unsimplified).node_count();
        CHECK(result.parked_bytes ==
              dem_bytes + 4 * nv + 4 * n + 4 * nv + nv + 4 * nv + 4 * nv + 4 * nodes);
        // The DEM waits on disk through the field (which does not read it), alone, and
        // through the division of the absorbed vertices, with the labels as grown.
        CHECK(result.parked_field == (std::string(field) == "height" ? 0 : dem_bytes));
        CHECK(result.parked_growing == dem_bytes + 4 * nv);
        // The file holds no more than the most parked at once (through the contour tree's
        // sweeps, more than at the simplification's peak): an array read back leaves a gap
        // the next ones fill (appended, the file would hold the DEM twice, the areas twice,
        // the sweeps' lists). Each of the at most 9 arrays parked at once starts on a 4 KiB
        // block (the file is read and written around the page cache): at most a block's
        // padding each.
        // Through the join and split sweeps: the DEM, the areas, the field (back after them
        // for contour tracking, with a hole), the Reeb graph's vertex lists, offsets,
        // vertices' nodes and node values, and the pixel maps.
        const std::size_t sweeps = dem_bytes + 4 * nv + 4 * nv + 4 * nv + 4 * (nodes + 1) + 4 * nv +
                                   4 * nodes + 4 * n + 4 * nv;
        CHECK(result.parked_most == std::max(sweeps, result.parked_bytes));
        CHECK(result.parked_file >= result.parked_most);
        CHECK(result.parked_file <= result.parked_most + 9 * 4096);
        const auto held = pipeline::segment(pipeline::input_from_dem(dem, MeshFrame::map), holding);
        CHECK(result.label_pixels() == held.label_pixels());
        CHECK(result.field == held.field);
        CHECK(result.segmentation.labels == held.segmentation.labels);
        const auto &m = result.input.mesh, &h = held.input.mesh;
        CHECK(m.pixel_vertex == h.pixel_vertex);
        CHECK(m.vertex_pixel == h.vertex_pixel);
        CHECK(m.neighbor_directions == h.neighbor_directions);
        CHECK(m.positions() == h.positions());
        // (The vertices' areas are parked through the Reeb graph, back for the simplification.)
        CHECK(!m.vertex_areas.empty());
        CHECK(m.vertex_areas == h.vertex_areas);
        CHECK(result.after.critical == held.after.critical);
        CHECK(result.critical_before == held.critical_before);
        CHECK(held.parked_bytes == 0);
        CHECK(held.parked_field == 0);
        CHECK(held.parked_growing == 0);
        CHECK(held.parked_file == 0);
        CHECK(std::distance(fs::directory_iterator(parking.park_directory), {}) == 0);
    }
}

TEST_CASE("pipeline options are checked before any work", "[pipeline]") {
    pipeline::SegmentOptions options;
    options.simplify.persistence = -1;
    CHECK_THROWS_WITH(pipeline::check_options(options),
                      "segment: --persistence must be a number >= 0");
    options = {};
    options.min_area = pipeline::MinArea::area(-2);
    CHECK_THROWS_WITH(pipeline::check_options(options),
                      "segment: --min-area takes an area above 0 in m^2 or with a unit (5km2, "
                      "2000m2, 3ha); '-2' is not one");
    CHECK_THROWS_AS(pipeline::segment(pipeline::Input{}, options), Error);
    CHECK_THROWS_AS(pipeline::parse_area_ratios("0.5,200"), Error);
    CHECK(pipeline::parse_area_ratios("1,0.25,1") == std::vector<double>{0.25, 1});
}

TEST_CASE("A cancelled segmentation throws and leaves no directory", "[pipeline]") {
    const auto dir = test::scratch_dir("pipeline_cancel");
    const auto out = dir / "out";
    CHECK_THROWS_WITH(pipeline::segment_to_directory(
                          test::sample("moon_ldem4_copernicus.tif"), out.string(), false, {}, {},
                          [](double f, std::string_view) { return f < 0.5; }),
                      Catch::Contains("cancelled"));
    CHECK_FALSE(fs::exists(out));
    std::size_t entries = 0;
    for (const auto& e : fs::directory_iterator(dir)) entries += e.exists() ? 1 : 0;
    CHECK(entries == 0);  // the temporary directory is gone too
}

TEST_CASE("pipeline::sweep: scales in order, lineage between neighbours", "[pipeline]") {
    const std::string path = test::sample("moon_ldem4_copernicus.tif");
    pipeline::SegmentOptions options;
    auto result = pipeline::sweep(pipeline::load_input(path), {2, 0.25, 0.5}, options);
    REQUIRE(result.scales.size() == 3);
    CHECK(result.scales[0].name == "0.25");
    CHECK(result.scales[2].name == "2");
    for (std::size_t i = 0; i + 1 < result.scales.size(); ++i)
        CHECK(result.scales[i].segmentation.region_count >=
              result.scales[i + 1].segmentation.region_count);
    REQUIRE(result.lineage.size() == 2);
    for (std::size_t i = 0; i < 2; ++i) {
        CHECK(result.lineage[i].size() == result.scales[i].segmentation.region_count);
        for (const auto& r : result.lineage[i]) {
            double sum = 0;
            for (const auto& o : r.overlaps) sum += o.fraction;
            CHECK(sum == Approx(1.0).epsilon(1e-6));
        }
    }
    // The finest scale is the segmentation `segment` gives at that ratio; the coarser ones
    // continue from it, so they are not (the threshold alone would give other regions).
    options.simplify.area_ratio = 0.25;
    const auto single = pipeline::segment(pipeline::load_input(path), options);
    CHECK(single.segmentation.labels == result.scales[0].segmentation.labels);
    // Each region's parent is its largest overlap.
    for (std::size_t i = 0; i < 2; ++i)
        for (const auto& r : result.lineage[i]) {
            REQUIRE(r.parent >= 1);
            CHECK(r.parent <= result.scales[i + 1].segmentation.region_count);
            for (const auto& o : r.overlaps) CHECK(o.fraction <= r.parent_share);
        }

    const auto dir = test::scratch_dir("pipeline_sweep");
    const auto files = pipeline::write_sweep_directory(result, options, path, dir.string());
    for (const char* f : {"labels.tif", "regions.gpkg", "lineage.json", "sweep.csv", "run.json"})
        CHECK(std::find(files.begin(), files.end(), f) != files.end());
    for (const auto& f : files) CHECK(fs::exists(dir / f));
}

TEST_CASE("pipeline::sweep nests its scales: counts never rise over 20 thresholds",
          "[pipeline][sweep][nested]") {
    // Each scale continues from the finer one's simplified graph. On the Vesta tile the
    // independent scales of before gave counts that rose between neighbouring thresholds
    // (as on the SRTM tile: 98 regions at 0.41 %, 152 at 0.53 %).
    std::vector<double> ratios;
    for (int i = 0; i < 20; ++i) ratios.push_back(0.05 * std::pow(1.3, i));
    for (const char* sample : {"vesta_hamo_tile.lbl", "moon_ldem4_copernicus.tif"}) {
        INFO(sample);
        const auto result = pipeline::sweep(pipeline::load_input(test::sample(sample)), ratios, {});
        REQUIRE(result.scales.size() == 20);
        for (std::size_t i = 0; i + 1 < result.scales.size(); ++i) {
            INFO("scale " << i);
            CHECK(result.scales[i].after.critical >= result.scales[i + 1].after.critical);
            CHECK(result.scales[i].after.minima + result.scales[i].after.maxima >=
                  result.scales[i + 1].after.minima + result.scales[i + 1].after.maxima);
            CHECK(result.scales[i].segmentation.region_count >=
                  result.scales[i + 1].segmentation.region_count);
        }
        CHECK(result.scales.front().segmentation.region_count >
              2 * result.scales.back().segmentation.region_count);
        // Regions mostly lie inside their parent: the area-weighted share, over the links.
        double share = 0;
        for (const auto& link : result.lineage) share += segment::mean_parent_share(link);
        share /= static_cast<double>(result.lineage.size());
        WARN(sample << ": mean parent share " << share);
        CHECK(share > 0.9);
    }
}

TEST_CASE("Continuing a simplification never adds extrema (noisy fields, 20 thresholds)",
          "[reeb][nested]") {
    // What the sweep relies on, on the graph alone: simplifying the simplified graph at a
    // higher threshold, again and again, on noisy planes.
    for (unsigned seed : {1u, 2u, 3u}) {
        const auto dem = test::grid_dem(120, 100, [](int, int) { return 0.0; });
        const auto mesh = mesh::dem_to_mesh(dem);
        const auto field = test::noise_field(mesh.vertex_count(), seed);
        auto graph = reeb::build_reeb_graph(mesh, field);
        std::size_t last = reeb::summarize(graph).minima + reeb::summarize(graph).maxima;
        for (int i = 0; i < 20; ++i) {
            reeb::SimplifyOptions o;
            o.persistence = 2 + i;
            o.area_ratio = 0.01 * std::pow(1.4, i);
            auto next = reeb::simplify(mesh, graph, o);
            const auto s = reeb::summarize(next.graph);
            INFO("seed " << seed << " step " << i);
            CHECK(s.minima + s.maxima <= last);
            last = s.minima + s.maxima;
            graph = std::move(next.graph);
        }
        CHECK(last < 50);
    }
}

TEST_CASE("pipeline::segment on a large grid: every stage reports, never going back",
          "[pipeline]") {
    // 640 x 640 pixels of noisy hills: every pass of every stage (2^18 items) and every slice
    // of the large blocks reports, so that a grid 600 times larger is never long silent
    // (docs/performance.md, "Progress on long runs"; tests/bench/progress_gaps.py measures it).
    const Dem dem = test::grid_dem(640, 640, [](int c, int r) {
        return 40 * std::sin(c * 0.03) * std::cos(r * 0.025) + ((c * 7919 + r * 104729) % 17) * 0.3;
    });
    std::vector<double> seen;
    std::vector<std::string> said;
    std::set<std::string> reported;
    const auto progress = [&](double f, std::string_view m) {
        seen.push_back(f);
        said.emplace_back(m);
        reported.insert(std::string(m));
        return true;
    };
    auto input = pipeline::input_from_dem(dem, MeshFrame::map, scaled_progress(progress, 0, 0.2));
    const auto result = pipeline::segment(std::move(input), {}, scaled_progress(progress, 0.2, 1));
    CHECK(result.segmentation.region_count > 1);
    CHECK(std::is_sorted(seen.begin(), seen.end()));
    CHECK(seen.back() == Approx(1.0));
    CHECK(seen.size() > 200);
    std::size_t widest = 1;  // the call after the widest step
    for (std::size_t i = 1; i < seen.size(); ++i)
        if (seen[i] - seen[i - 1] > seen[widest] - seen[widest - 1]) widest = i;
    INFO("from " << said[widest - 1] << " at " << seen[widest - 1] << " to " << said[widest]);
    // (The cancellations report on a clock, every quarter second: on this small grid they
    // take less, and their slice, 0.08 of the bar, passes in one step. Nothing else may.)
    CHECK(seen[widest] - seen[widest - 1] < 0.081);
    for (const char* stage :
         {"mesh", "shape index", "reeb: order", "reeb: links", "reeb: join and split trees",
          "reeb: arcs", "simplify", "grow", "divide", "regions"}) {
        INFO(stage);
        CHECK(reported.count(stage) == 1);
    }
}

TEST_CASE("pipeline::segment: a mesh file's defaults are the paper's, absorbed nodes whole",
          "[pipeline]") {
    // The landform defaults are for DEMs: a closed mesh with no option keeps the paper's
    // behaviour (the shape diameter function or any field, the absorbed nodes whole), the
    // same labels as --absorbed whole, other labels than --absorbed divide.
    const auto run = [](const std::string& absorbed) {
        pipeline::Input input;
        input.mesh = test::torus_mesh(3, 1, 96, 48, false);
        // Bumps on it, so that the simplification cancels and absorbs.
        for (auto& p : input.mesh.edit_positions())
            p[2] += 0.3f * float(std::sin(5 * std::atan2(double(p[1]), double(p[0])) + p[2]) +
                                 0.2 * std::sin(40.0 * p[0]));
        pipeline::SegmentOptions options;
        options.landform_defaults = true;  // as the command line sets it with no scale option
        options.field = field::FieldKind::height;
        options.simplify.persistence = 0.02;
        options.simplify.area_ratio = 2;
        options.absorbed = pipeline::parse_absorbed(absorbed.empty() ? "auto" : absorbed);
        return pipeline::segment(std::move(input), options);
    };
    const auto by_default = run("");
    const auto whole = run("whole");
    const auto divide = run("divide");
    INFO(by_default.segmentation.region_count << " regions, " << by_default.after.critical
                                              << " critical");
    CHECK_FALSE(by_default.regions.has_field_scale);
    CHECK_FALSE(by_default.regions.has_area_range);
    CHECK(by_default.segmentation.labels == whole.segmentation.labels);
    CHECK(by_default.divided.absorbed == 0);
    CHECK(divide.divided.absorbed > 0);
    CHECK(divide.segmentation.labels != whole.segmentation.labels);
}
