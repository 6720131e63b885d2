#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "support/test_meshes.hpp"
#include "terrain/core/error.hpp"
#include "terrain/pipeline/segment.hpp"
#include "terrain/segment/craters.hpp"

using namespace terrain;

namespace {

// A paraboloid bowl of radius R and depth `depth` whose rim rises `rim` above a plane, centred
// at (cx, cy) in pixel coordinates (1 m pixels, no CRS): the rim crest is the circle of radius
// R, `depth + rim` above the bowl's bottom. With a `swing`, the rim rises and falls by it three
// times round the circle.
Dem bowl_dem(int size, double cx, double cy, double R, double depth, double rim, double swing = 0) {
    return test::grid_dem(size, size, [=](int c, int r) {
        const double x = c + 0.5 - cx, y = r + 0.5 - cy, d = std::hypot(x, y);
        const double bowl = d < R ? depth * ((d / R) * (d / R) - 1) : 0.0;
        const double w = (d - R) / (0.3 * R);
        const double crest = rim + swing * std::cos(3 * std::atan2(y, x));
        return bowl + crest * std::exp(-w * w);
    });
}

pipeline::SegmentResult segment_dem(Dem dem) {
    pipeline::SegmentOptions options;
    options.landform_defaults = true;
    return pipeline::segment(pipeline::input_from_dem(std::move(dem)), options);
}

}  // namespace

TEST_CASE("Craters: an analytic bowl's centre, diameter and depth", "[craters]") {
    for (const double R : {12.0, 30.0}) {
        const double cx = 80.3, cy = 79.6, depth = 0.2 * R, rim = 0.04 * R;
        auto result = segment_dem(bowl_dem(160, cx, cy, R, depth, rim));
        REQUIRE(result.craters);
        const auto& table = result.craters->craters;
        INFO("R = " << R << " px, " << table.size() << " craters");
        REQUIRE(!table.empty());
        CHECK_FALSE(result.craters->lonlat);
        // The most confident is the bowl.
        const auto& k = *std::max_element(
            table.begin(), table.end(),
            [](const auto& a, const auto& b) { return a.confidence < b.confidence; });
        CHECK(std::hypot(k.col - cx, k.row - cy) < 1.0);
        CHECK(k.diameter_m == Approx(2 * R).epsilon(0.05));
        CHECK(k.depth_m == Approx(depth + rim).epsilon(0.05));
        CHECK(k.rim_fraction > 0.9);
        CHECK(k.confidence > 0.6);
        // Map coordinates without a CRS: the grid's x and y of the centre.
        const auto xy = result.dem()->map_xy(k.col, k.row);
        CHECK(k.lon == Approx(xy[0]));
        CHECK(k.lat == Approx(xy[1]));
        // The rim ring: closed, on the bowl's rim (1 m pixels: map units are metres).
        REQUIRE(k.rim.size() == std::size_t(segment::kRimPoints) + 1);
        CHECK(k.rim.front() == k.rim.back());
        const auto truth = result.dem()->map_xy(cx, cy);
        for (const auto& p : k.rim)
            CHECK(std::abs(std::hypot(p[0] - truth[0], p[1] - truth[1]) - R) < 1.5);
        // The floor is concave and its rims convex.
        const auto& floor = result.regions.regions[k.floor_region - 1];
        CHECK(floor.field_mean < 50);
        REQUIRE(!k.rim_regions.empty());
        for (const auto r : k.rim_regions) CHECK(result.regions.regions[r - 1].field_mean > 50);
    }
}

TEST_CASE("Craters: a plane and a dome have none, and off gives no table", "[craters]") {
    auto plane =
        segment_dem(test::grid_dem(96, 96, [](int c, int r) { return 0.01 * c + 0.02 * r; }));
    REQUIRE(plane.craters);
    CHECK(plane.craters->craters.empty());
    auto dome = segment_dem(bowl_dem(120, 60, 60, 25, -5, 0));  // (a negative depth: a dome)
    REQUIRE(dome.craters);
    CHECK(dome.craters->craters.empty());
    pipeline::SegmentOptions off;
    off.landform_defaults = true;
    off.craters = false;
    const auto none =
        pipeline::segment(pipeline::input_from_dem(bowl_dem(96, 48, 48, 12, 3, 0.5)), off);
    CHECK_FALSE(none.craters);
}

TEST_CASE("Craters: sizes that do not match are refused", "[craters]") {
    const auto dem = bowl_dem(40, 20, 20, 8, 2, 0.3);
    auto result = segment_dem(dem);
    auto labels = result.segmentation.labels;
    labels.pop_back();
    CHECK_THROWS_AS(segment::find_craters(result.input.mesh, *result.dem(), labels, result.regions),
                    Error);
}

namespace {

// The craters of `result` after its labels were changed: the region graph made again.
segment::CraterTable craters_of(const pipeline::SegmentResult& result,
                                const std::vector<std::uint32_t>& labels, std::uint32_t count) {
    const auto graph =
        segment::region_graph(result.input.mesh, result.field, labels, count, result.dem());
    return segment::find_craters(result.input.mesh, *result.dem(), labels, graph);
}

// The floor region of the most confident crater of a segmentation.
std::uint32_t best_floor(const pipeline::SegmentResult& result) {
    REQUIRE(result.craters);
    const auto& table = result.craters->craters;
    REQUIRE(!table.empty());
    return std::max_element(
               table.begin(), table.end(),
               [](const auto& a, const auto& b) { return a.confidence < b.confidence; })
        ->floor_region;
}

// How many craters of `table` read the bowl of radius R at (cx, cy): the centre within R / 4,
// the diameter within 10 %.
std::ptrdiff_t count_near(const segment::CraterTable& table, double cx, double cy, double R) {
    return std::count_if(table.craters.begin(), table.craters.end(), [&](const auto& k) {
        return std::hypot(k.col - cx, k.row - cy) < 0.25 * R &&
               k.diameter_m == Approx(2 * R).epsilon(0.1);
    });
}

// The segmentation's labels with its most confident crater's floor cut at (cx, cy) into an
// east and a west half (pieces 2) or four quarters (pieces 4), each piece but the north-west
// one a new region after the segmentation's; `count` the regions then.
std::vector<std::uint32_t> cut_floor(const pipeline::SegmentResult& result, double cx, double cy,
                                     int pieces, std::uint32_t& count) {
    const auto floor = best_floor(result);
    auto labels = result.segmentation.labels;
    const auto first = std::uint32_t(result.regions.regions.size()) + 1;
    const auto width = std::size_t(result.dem()->width);
    std::array<std::size_t, 3> moved{};
    for (std::size_t v = 0; v < labels.size(); ++v) {
        if (labels[v] != floor) continue;
        const auto pixel = std::size_t(result.input.mesh.vertex_pixel[v]);
        const bool east = double(pixel % width) + 0.5 > cx,
                   south = pieces == 4 && double(pixel / width) + 0.5 > cy;
        const int piece = (east ? 1 : 0) + (south ? 2 : 0);  // 0: the floor's own region
        if (piece == 0) continue;
        labels[v] = first + std::uint32_t(piece - 1);
        ++moved[std::size_t(piece - 1)];
    }
    for (int k = 0; k + 1 < pieces; ++k) REQUIRE(moved[std::size_t(k)] > 100);
    count = first + std::uint32_t(pieces - 2);
    return labels;
}

}  // namespace

TEST_CASE("Craters: a floor cut in pieces by the segmentation is one crater", "[craters]") {
    // A floor cut in two halves, or in quarters round its centre (a large crater's small
    // craters, terraces and peaks each an extremum: no quarter and no half is round, the four
    // quarters are).
    const double cx = 80.3, cy = 79.6, R = 30, depth = 6, rim = 1.2;
    auto result = segment_dem(bowl_dem(160, cx, cy, R, depth, rim));
    for (const int pieces : {2, 4}) {
        std::uint32_t count = 0;
        const auto labels = cut_floor(result, cx, cy, pieces, count);
        const auto table = craters_of(result, labels, count);
        INFO(pieces << " pieces, " << table.craters.size() << " craters");
        CHECK(count_near(table, cx, cy, R) == 1);
    }
}

TEST_CASE("Craters: two floors side by side stay two craters", "[craters]") {
    // Two bowls whose rims touch: their floors are adjacent concave regions of equal areas;
    // each is a crater of its own and none spans both.
    const double R = 20, depth = 4, rim = 0.8;
    const double ax = 60.3, bx = 100.7, y = 60.2;
    const auto dem = test::grid_dem(160, 120, [=](int c, int r) {
        double z = 0;
        for (const double cx : {ax, bx}) {
            const double d = std::hypot(c + 0.5 - cx, r + 0.5 - y);
            const double w = (d - R) / (0.3 * R);
            z += (d < R ? depth * ((d / R) * (d / R) - 1) : 0.0) + rim * std::exp(-w * w);
        }
        return z;
    });
    auto result = segment_dem(dem);
    REQUIRE(result.craters);
    const auto& table = result.craters->craters;
    INFO(table.size() << " craters");
    for (const double cx : {ax, bx})
        CHECK(std::count_if(table.begin(), table.end(), [&](const auto& k) {
                  return std::hypot(k.col - cx, k.row - y) < 0.25 * R &&
                         k.diameter_m == Approx(2 * R).epsilon(0.1);
              }) == 1);
    // No crater spans both.
    for (const auto& k : table) CHECK(k.diameter_m < 3 * R);
}

TEST_CASE("Craters: the confidence's terms", "[craters]") {
    segment::CraterEvidence e;
    e.rim_fraction = 0.75;
    e.radius_m = 40;
    e.pixel_m = 10;
    e.circularity = 0.8;
    e.floor_mean = 30;
    // Half a pixel of RMS is the grid's: no misfit.
    e.fit_rms_m = 5;
    CHECK(segment::crater_confidence(e) == Approx(0.75));
    // Beyond it, the misfit: sqrt(13^2 - 5^2) = 12 m on a 40 m radius, quality 1 - 1.2 -> 0.
    e.fit_rms_m = 13;
    CHECK(segment::crater_confidence(e) == 0);
    e.fit_rms_m = std::sqrt(25.0 + 16.0);  // misfit 4 m: quality 0.6
    CHECK(segment::crater_confidence(e) == Approx(0.75 * 0.6));
    e.fit_rms_m = 0;
    // Roundness: circularity 0.2 of the 0.4 that takes the whole.
    e.circularity = 0.2;
    CHECK(segment::crater_confidence(e) == Approx(0.375));
    e.circularity = 1;
    // Concavity: a floor at 43.75 or below has it all, at 50 none, half way half.
    for (const auto& [mean, share] : std::vector<std::pair<double, double>>{
             {43.75, 1}, {20, 1}, {46.875, 0.5}, {50, 0}, {60, 0}})
        CHECK(segment::crater_confidence({0.75, 0, 40, 10, 1, mean}) == Approx(0.75 * share));
    // Level: a rim whose heights spread as much as the crater is deep keeps half, one that
    // cannot be measured (off the grid, or a centre not below it) none.
    e.floor_mean = 30;
    e.rim_spread = 1;
    CHECK(segment::crater_confidence(e) == Approx(0.375));
    e.rim_spread = 0.5;
    CHECK(segment::crater_confidence(e) == Approx(0.75 / 1.25));
    e.rim_spread = std::numeric_limits<double>::infinity();
    CHECK(segment::crater_confidence(e) == 0);
}

TEST_CASE("Craters: a low between uneven rims is less confident than a level crater", "[craters]") {
    // The same bowl twice: once under a level rim, once under a rim that rises and falls
    // three times round it by twice the bowl's depth, as the rims of other craters round a
    // low between them do.
    const double R = 14, cx = 60.3, cy = 59.6, depth = 0.2 * R, rim = 0.04 * R;
    const auto best = [&](double swing) {
        auto result = segment_dem(bowl_dem(120, cx, cy, R, depth, rim, swing));
        REQUIRE(result.craters);
        double confidence = 0;  // of the crater at the bowl, 0 when none is listed there
        for (const auto& k : result.craters->craters)
            if (std::hypot(k.col - cx, k.row - cy) < 0.5 * R)
                confidence = std::max(confidence, k.confidence);
        return confidence;
    };
    const double level = best(0), uneven = best(2 * depth);
    INFO("level " << level << ", uneven " << uneven);
    CHECK(level > 0.6);
    CHECK(uneven < 0.5 * level);
}

TEST_CASE("Craters: a bowl a few pixels wide is listed", "[craters]") {
    // A floor of a few dozen pixels, a rim sampled by a vertex or two in each direction.
    for (const double R : {4.0, 5.0}) {
        const double cx = 30.3, cy = 29.6;
        auto result = segment_dem(bowl_dem(60, cx, cy, R, 0.2 * R, 0.04 * R));
        REQUIRE(result.craters);
        const auto& table = result.craters->craters;
        INFO("R = " << R << " px, " << table.size() << " craters");
        CHECK(std::count_if(table.begin(), table.end(), [&](const auto& k) {
                  return std::hypot(k.col - cx, k.row - cy) < 0.5 * R &&
                         k.diameter_m == Approx(2 * R).epsilon(0.25);
              }) == 1);
    }
}

TEST_CASE("Craters: a small bowl's whole rim reads as whole", "[craters]") {
    // A rim of a few pixels' radius has fewer pixels than 36 directions: the directions are
    // one a pixel of the floor's circle, so a complete rim still fills most of them.
    for (const double R : {4.0, 5.0, 6.0}) {
        const double cx = 30.3, cy = 29.6;
        auto result = segment_dem(bowl_dem(60, cx, cy, R, 0.2 * R, 0.04 * R));
        REQUIRE(result.craters);
        const auto& table = result.craters->craters;
        INFO("R = " << R << " px, " << table.size() << " craters");
        const auto k = std::find_if(table.begin(), table.end(), [&](const auto& c) {
            return std::hypot(c.col - cx, c.row - cy) < 0.5 * R;
        });
        REQUIRE(k != table.end());
        CHECK(k->rim_fraction >= 0.8);
    }
}

TEST_CASE("Craters: a floor round a central peak is one crater", "[craters]") {
    // A complex crater: the bowl with a peak at its centre; the floor is a ring round it,
    // inside the rim.
    const double cx = 80.3, cy = 79.6, R = 30, depth = 6, rim = 1.2;
    const auto dem = test::grid_dem(160, 160, [=](int c, int r) {
        const double d = std::hypot(c + 0.5 - cx, r + 0.5 - cy);
        const double bowl = d < R ? depth * ((d / R) * (d / R) - 1) : 0.0;
        const double w = (d - R) / (0.3 * R), p = d / (0.15 * R);
        return bowl + rim * std::exp(-w * w) + 0.6 * depth * std::exp(-p * p);
    });
    auto result = segment_dem(dem);
    REQUIRE(result.craters);
    const auto& table = result.craters->craters;
    INFO(table.size() << " craters");
    CHECK(std::count_if(table.begin(), table.end(), [&](const auto& k) {
              return std::hypot(k.col - cx, k.row - cy) < 0.25 * R &&
                     k.diameter_m == Approx(2 * R).epsilon(0.1);
          }) == 1);
}
