// The options' values and their names (terrain/pipeline/options.hpp and the tables beside the
// enumerations): every value read back from the name it is written with, "auto" left unset,
// and the one line a bad name gives, which the command line and the Python module print.
#include <catch2/catch.hpp>

#include <optional>
#include <string>

#include "terrain/core/dem.hpp"
#include "terrain/core/error.hpp"
#include "terrain/pipeline/options.hpp"

using namespace terrain;

TEST_CASE("every option's value is read back from its name", "[pipeline][options]") {
    std::size_t kinds = 0;
    for (const auto& [name, kind] : field::kFieldKindNames) {
        CHECK(field::parse_field_kind(name) == kind);
        CHECK(std::string(field::to_string(kind)) == name);
        ++kinds;
    }
    CHECK(kinds == 3);  // shape-index, sdf, height
    for (const auto& [name, cost] : segment::kGrowCostNames) {
        CHECK(pipeline::parse_cost(name) == cost);
        CHECK(pipeline::name_or_auto(std::optional(cost)) == name);
    }
    for (const auto& [name, absorbed] : pipeline::kAbsorbedNames) {
        CHECK(pipeline::parse_absorbed(name) == absorbed);
        CHECK(pipeline::name_or_auto(std::optional(absorbed)) == name);
    }
    for (const auto& [name, frame] : pipeline::kFrameNames) {
        CHECK(pipeline::parse_frame(name) == frame);
        CHECK(std::string(to_string(frame)) == name);  // the mesh's own name of its frame
    }
    for (const auto& [name, window] : field::kShapeIndexWindowNames) {
        CHECK(pipeline::parse_window(name) == window);
        CHECK(std::string(field::to_string(window)) == name);
    }
    for (const auto kind : {ElevationKind::height, ElevationKind::radius})
        CHECK(value_named(kElevationNames, to_string(kind)) == kind);
    // "auto": left to the input.
    CHECK_FALSE(pipeline::parse_cost("auto"));
    CHECK_FALSE(pipeline::parse_absorbed("auto"));
    CHECK_FALSE(pipeline::parse_frame("auto"));
    CHECK(pipeline::name_or_auto(std::optional<segment::GrowCost>()) == "auto");
    CHECK(pipeline::name_or_auto(std::optional<pipeline::Absorbed>()) == "auto");
}

TEST_CASE("an area threshold is none, auto or an area kept as written", "[pipeline][options]") {
    const auto none = pipeline::parse_min_area("");
    CHECK(none.kind == pipeline::MinArea::Kind::none);
    CHECK_FALSE(none.is_set());
    CHECK(pipeline::to_string(none).empty());
    const auto automatic = pipeline::parse_min_area("auto");
    CHECK(automatic.is_set());
    CHECK(automatic.is_auto());
    CHECK(pipeline::to_string(automatic) == "auto");
    CHECK(pipeline::to_string(pipeline::MinArea::automatic()) == "auto");
    for (const auto& [text, m2] : {std::pair{"150km2", 1.5e8},
                                   {"2.5 km^2", 2.5e6},
                                   {"20000ha", 2e8},
                                   {"150000000.0", 1.5e8}}) {
        const auto area = pipeline::parse_min_area(text);
        CHECK(area.kind == pipeline::MinArea::Kind::area);
        CHECK(area.m2 == m2);
        CHECK(pipeline::to_string(area) == text);  // as run.json and the preview write it
    }
    CHECK(pipeline::to_string(pipeline::MinArea::area(2500)) == "2500");
    CHECK(pipeline::to_string(pipeline::MinArea::area(2e6, "2km2")) == "2km2");
}

TEST_CASE("a bad name gives the command line's line", "[pipeline][options]") {
    const std::string area = " takes an area above 0 in m^2 or with a unit (5km2, 2000m2, 3ha); '";
    CHECK_THROWS_WITH(field::parse_field_kind("slope"),
                      "field: unknown field 'slope'; use shape-index, sdf or height");
    CHECK_THROWS_WITH(field::parse_field_kind("shape_index"),
                      "field: unknown field 'shape_index'; use shape-index, sdf or height");
    CHECK_THROWS_WITH(pipeline::parse_cost("cheap"),
                      "segment: unknown cost 'cheap'; use graph or standard");
    CHECK_THROWS_WITH(pipeline::parse_cost("AUTO"),
                      "segment: unknown cost 'AUTO'; use graph or standard");
    CHECK_THROWS_WITH(pipeline::parse_absorbed("bad"),
                      "segment: --absorbed is divide, whole or auto; 'bad' is none of them");
    CHECK_THROWS_WITH(pipeline::parse_frame("sideways"),
                      "mesh: the frame must be body, map or auto, not 'sideways'");
    CHECK_THROWS_WITH(pipeline::parse_window("cube"),
                      "options: --window must be disk or ball, not 'cube'");
    CHECK_THROWS_WITH(pipeline::parse_window("cube", "window"),
                      "options: window must be disk or ball, not 'cube'");
    CHECK_THROWS_WITH(pipeline::parse_min_area("5 furlongs"),
                      "segment: --min-area" + area + "5 furlongs' is not one");
    CHECK_THROWS_WITH(pipeline::parse_min_area("AUTO"),
                      "segment: --min-area" + area + "AUTO' is not one");
    CHECK_THROWS_WITH(pipeline::parse_min_area("0"),
                      "segment: --min-area" + area + "0' is not one");
    CHECK_THROWS_WITH(pipeline::parse_min_areas("1km2,x"),
                      "sweep: --min-areas" + area + "x' is not one");
    CHECK_THROWS_WITH(
        pipeline::parse_area_ratios("0.5,200"),
        "sweep: --area-ratios takes percentages in (0, 100] separated by commas; '200' is not one");
    CHECK_THROWS_WITH(pipeline::parse_area_ratios(""),
                      "sweep: --area-ratios needs at least one value");
}
