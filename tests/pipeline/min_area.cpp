// --min-area: area thresholds on the body (pipeline::parse_area, SegmentOptions::min_area,
// reeb::area_ratio_for_area), their equivalence with the area ratio, and the same crater kept
// whatever the tile's extent.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>

#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/geo/georeference.hpp"
#include "terrain/pipeline/segment.hpp"
#include "terrain/pipeline/sweep.hpp"
#include "terrain/reeb/simplify.hpp"
#include "terrain/synth/crater_field.hpp"

using namespace terrain;

TEST_CASE("parse_area reads m^2, km2, ha and refuses what is not an area", "[pipeline][min-area]") {
    CHECK(pipeline::parse_area("2000") == 2000);
    CHECK(pipeline::parse_area("2000m2") == 2000);
    CHECK(pipeline::parse_area("2000m^2") == 2000);
    CHECK(pipeline::parse_area("5km2") == 5e6);
    CHECK(pipeline::parse_area("0.5KM2") == 5e5);
    CHECK(pipeline::parse_area("2.5 km^2") == 2.5e6);
    CHECK(pipeline::parse_area("3ha") == 3e4);
    CHECK(pipeline::parse_area("1e6") == 1e6);
    for (const char* bad :
         {"", "km2", "abc", "5km", "5 acres", "5km2x", "-3km2", "0", "0km2", "nan", "inf", "1e400"})
        CHECK_THROWS_AS(pipeline::parse_area(bad), Error);
    CHECK_THROWS_AS(pipeline::parse_min_area("12 parsecs"), Error);
    pipeline::SegmentOptions options;
    options.min_area = pipeline::parse_min_area("12km2");
    CHECK(options.min_area.m2 == 12e6);
    CHECK_NOTHROW(pipeline::check_options(options));
    // Lists for the sweep: sorted by area, duplicates once, bad items named.
    const auto areas = pipeline::parse_min_areas("5km2,200ha,1km2,1000000");
    REQUIRE(areas.size() == 3);
    CHECK(areas[0].m2 == 1e6);
    CHECK(areas[0].text == "1km2");
    CHECK(areas[1].m2 == 2e6);
    CHECK(areas[2].text == "5km2");
    CHECK_THROWS_AS(pipeline::parse_min_areas("1km2,x"), Error);
    CHECK_THROWS_AS(pipeline::parse_min_areas(""), Error);
}

TEST_CASE("min_area X gives the labels of area ratio 100 X / A on a mesh of area A",
          "[pipeline][min-area]") {
    auto input = pipeline::load_input(test::sample("moon_ldem4_copernicus.tif"));
    const double A = reeb::total_area(input.mesh);
    double sum = 0;
    for (const float a : input.mesh.vertex_areas) sum += a;
    CHECK(A == sum);
    CHECK(A > 1e9);  // m^2 on the Moon: tens of thousands of km^2
    // An area of about 0.3 % of the tile, written in km^2.
    const double km2 = std::round(0.003 * A / 1e6);
    const std::string text = JsonWriter::number(km2) + "km2";
    const double X = km2 * 1e6;
    CHECK(reeb::area_ratio_for_area(input.mesh, X) == 100 * X / A);
    CHECK(reeb::area_ratio_for_area(input.mesh, 10 * A) == 100);  // capped

    pipeline::SegmentOptions by_area, by_ratio;
    by_area.min_area = pipeline::parse_min_area(text);
    by_ratio.simplify.area_ratio = 100 * X / A;
    const auto a =
        pipeline::segment(pipeline::load_input(test::sample("moon_ldem4_copernicus.tif")), by_area);
    const auto r = pipeline::segment(std::move(input), by_ratio);
    CHECK(a.area_ratio_percent == 100 * X / A);
    CHECK(a.segmentation.region_count == r.segmentation.region_count);
    CHECK(a.after.critical == r.after.critical);
    CHECK(a.segmentation.labels == r.segmentation.labels);
    CHECK(a.label_pixels() == r.label_pixels());
    // And it is not the default's 0.5 %: the option changed the result.
    const auto d =
        pipeline::segment(pipeline::load_input(test::sample("moon_ldem4_copernicus.tif")),
                          pipeline::SegmentOptions{});
    CHECK(d.segmentation.region_count != a.segmentation.region_count);
}

namespace {

// Columns [c0, c0 + n) and rows [r0, r0 + n) of `dem`, georeferenced.
Dem crop(const Dem& dem, int c0, int r0, int n) {
    Dem out = dem;
    out.width = out.height = n;
    out.values.assign(static_cast<std::size_t>(n) * static_cast<std::size_t>(n), 0.0);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            out.values[static_cast<std::size_t>(r * n + c)] = dem.at(c0 + c, r0 + r);
    const auto& t = dem.transform;
    out.transform[0] = t[0] + c0 * t[1] + r0 * t[2];
    out.transform[3] = t[3] + c0 * t[4] + r0 * t[5];
    geo::georeference(out);
    return out;
}

// Is the crater of radius `radius` pixels centred at (cx, cy) its own region: one label on
// nearly all of its floor (within 0.4 radius), on a region not much larger than the crater
// (its rim and the plains just outside, which the absorbed vertices' division shares among
// the regions around: 2.06 times the crater's area in the large tile)?
bool crater_kept(const pipeline::SegmentResult& result, double cx, double cy, double radius) {
    const Dem& dem = *result.dem();
    const auto pixels = result.label_pixels();
    std::map<std::uint32_t, int> floor;
    int n = 0;
    for (int r = 0; r < dem.height; ++r)
        for (int c = 0; c < dem.width; ++c)
            if (std::hypot(c + 0.5 - cx, r + 0.5 - cy) < 0.4 * radius) {
                ++floor[pixels[dem.index(c, r)]];
                ++n;
            }
    const auto top = std::max_element(floor.begin(), floor.end(),
                                      [](auto& a, auto& b) { return a.second < b.second; });
    const double crater_pixels = 3.14159 * radius * radius;
    std::size_t region_pixels = 0;
    for (const auto p : pixels) region_pixels += p == top->first;
    INFO("floor share " << double(top->second) / n << ", region " << region_pixels << " px, crater "
                        << crater_pixels << " px");
    return top->second >= 0.9 * n && double(region_pixels) < 2.5 * crater_pixels;
}

}  // namespace

TEST_CASE("the same crater is kept in a small and a large tile at the same --min-area",
          "[pipeline][min-area]") {
    // A cratered Vesta tile with one 2.5 km crater (about 36 pixels across) at the centre.
    synth::VestaTileOptions o;
    o.width = o.height = 240;
    const double pixel = 69.54;
    o.craters.push_back(synth::Crater{120.0, 120.0, 2500.0, 0.0, 0.0});
    Dem large = synth::generate_vesta_tile(o);
    geo::georeference(large);
    const double radius = 1250.0 / pixel;
    const Dem small = crop(large, 80, 80, 80);

    pipeline::SegmentOptions by_area;
    by_area.min_area = pipeline::parse_min_area("2km2");  // below the crater's 4.9 km^2
    const auto s = pipeline::segment(pipeline::input_from_dem(small), by_area);
    const auto l = pipeline::segment(pipeline::input_from_dem(large), by_area);
    CHECK(crater_kept(s, 40, 40, radius));
    CHECK(crater_kept(l, 120, 120, radius));
    // The small tile's equivalent area ratio, used on the large tile, is nine times the
    // area there: the crater is lost. That is what --min-area is for.
    pipeline::SegmentOptions by_ratio;
    by_ratio.simplify.area_ratio = s.area_ratio_percent;
    CHECK(s.area_ratio_percent > 5 * l.area_ratio_percent);
    const auto lr = pipeline::segment(pipeline::input_from_dem(large), by_ratio);
    CHECK_FALSE(crater_kept(lr, 120, 120, radius));
}

TEST_CASE("pipeline::sweep over areas: each scale is a segment at that --min-area",
          "[pipeline][min-area][sweep]") {
    const std::string path = test::sample("moon_ldem4_copernicus.tif");
    pipeline::SegmentOptions options;
    const auto areas = pipeline::parse_min_areas("400km2,100km2");
    const auto sweep = pipeline::sweep(pipeline::load_input(path), areas, options);
    REQUIRE(sweep.scales.size() == 2);
    CHECK(sweep.scales[0].name == "100km2");
    CHECK(sweep.scales[0].min_area_m2 == 1e8);
    CHECK(sweep.scales[0].ratio < sweep.scales[1].ratio);
    // The finest scale is a segment at its area; the coarser one continues from it.
    options.min_area = pipeline::parse_min_area("100km2");
    const auto one = pipeline::segment(pipeline::load_input(path), options);
    CHECK(sweep.scales[0].ratio == one.area_ratio_percent);
    CHECK(sweep.scales[0].segmentation.labels == one.segmentation.labels);
    options.min_area = pipeline::parse_min_area("400km2");
    const auto coarse = pipeline::segment(pipeline::load_input(path), options);
    CHECK(sweep.scales[1].ratio == coarse.area_ratio_percent);
    CHECK(sweep.scales[0].segmentation.region_count >= sweep.scales[1].segmentation.region_count);
}
