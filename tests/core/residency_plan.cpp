// The memory plan and its stage table (terrain/internal/core/residency_plan.hpp): on entering
// a stage every bound array it reads is in memory with its values and every other one is out,
// stages come in order, and an array's needs come back before it.
#include <catch2/catch.hpp>

#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/residency_plan.hpp"

using terrain::Stage;
using terrain::detail::Held;
using terrain::detail::ParkedArrays;
using terrain::detail::ResidencyPlan;
using terrain::detail::stage_reads;

namespace {

constexpr Stage stage_at(std::size_t i) {
    return static_cast<Stage>(i);
}

// Every array of the table bound as a vector of its own, with distinct values.
struct Arrays {
    std::vector<std::vector<std::int32_t>> values;
    Arrays() {
        for (std::size_t a = 0; a < terrain::detail::kHeldCount; ++a) {
            values.emplace_back(1000 + 37 * a);
            std::iota(values.back().begin(), values.back().end(), std::int32_t(a * 100000));
        }
    }
    void bind(ResidencyPlan& plan) {
        for (std::size_t a = 0; a < values.size(); ++a)
            plan.bind(Held(a), values[a], values[a].size() * sizeof(std::int32_t));
    }
    bool intact(std::size_t a) const {
        for (std::size_t i = 0; i < values[a].size(); ++i)
            if (values[a][i] != std::int32_t(a * 100000 + i)) return false;
        return values[a].size() == 1000 + 37 * a;
    }
};

}  // namespace

TEST_CASE("The stage table keeps what the stages after the field need", "[core][residency]") {
    // The region graph reads everything but the triangles (made again from the grid); the
    // Reeb graph and the simplification read neither the DEM nor the positions; the copy of
    // the arcs and the cancellations (the simplification's peak) read none of the arrays.
    for (std::size_t a = 0; a < terrain::detail::kHeldCount; ++a) {
        INFO(terrain::detail::held_name(Held(a)));
        CHECK(stage_reads(Stage::regions, Held(a)) == (Held(a) != Held::triangles));
        CHECK_FALSE(stage_reads(Stage::simplify_arcs, Held(a)));
        CHECK_FALSE(stage_reads(Stage::simplify_output, Held(a)));
    }
    for (const Stage s :
         {Stage::reeb_events, Stage::reeb_links, Stage::reeb_sweeps, Stage::reeb_arcs,
          Stage::reeb_loops, Stage::simplify_nodes, Stage::grow}) {
        CHECK_FALSE(stage_reads(s, Held::dem));
        CHECK_FALSE(stage_reads(s, Held::positions));
    }
    // Only the height field reads the DEM before the region graph; only the SDF and contour
    // tracking read the triangles.
    for (std::size_t s = 0; s + 1 < terrain::kStageCount; ++s) {
        CHECK(stage_reads(stage_at(s), Held::dem) == (stage_at(s) == Stage::height_field));
        CHECK(stage_reads(stage_at(s), Held::triangles) ==
              (stage_at(s) == Stage::sdf || stage_at(s) == Stage::reeb_loops));
    }
    // Each array is read by some stage after its last write, and the labels only from the
    // growing on.
    CHECK_FALSE(stage_reads(Stage::flood, Held::labels));
    CHECK(stage_reads(Stage::relabel, Held::labels));
}

TEST_CASE("On entering a stage, the arrays it reads are in memory and no other",
          "[core][residency]") {
    const auto dir = terrain::test::scratch_dir("residency_plan");
    Arrays arrays;
    ResidencyPlan plan(dir.string(), 0);
    arrays.bind(plan);
    for (std::size_t s = 0; s < terrain::kStageCount; ++s) {
        if (stage_at(s) == Stage::height_field || stage_at(s) == Stage::sdf) continue;
        INFO("stage " << s);
        plan.enter(stage_at(s));
        std::size_t out = 0;
        for (std::size_t a = 0; a < arrays.values.size(); ++a) {
            INFO(terrain::detail::held_name(Held(a)));
            const bool read = stage_reads(stage_at(s), Held(a));
            CHECK(plan.resident(Held(a)) == read);
            if (read)
                CHECK(arrays.intact(a));
            else
                CHECK(arrays.values[a].empty());  // (parked: read now, it would be empty)
            if (!read) out += (1000 + 37 * a) * sizeof(std::int32_t);
        }
        CHECK(plan.parked_in(stage_at(s)) == out);
    }
    CHECK(plan.store().parked_bytes() == 4 * (1000 + 37 * std::size_t(Held::triangles)));
}

TEST_CASE("Stages come in order, and an array's needs come back before it", "[core][residency]") {
    const auto dir = terrain::test::scratch_dir("residency_order");
    ResidencyPlan plan(dir.string(), 0);
    std::string calls;
    const auto holder = [&](char name, Held needs) {
        ResidencyPlan::Holder h;
        h.hold = [&calls, name](ParkedArrays&, const terrain::ProgressFn&) {
            calls += std::string("-") + name;
            return true;
        };
        h.back = [&calls, name](ParkedArrays&, const terrain::ProgressFn&) {
            calls += std::string("+") + name;
        };
        h.needs = needs;
        h.bytes = [] { return std::size_t{100}; };
        return h;
    };
    plan.bind(Held::dem, holder('d', Held::count));
    plan.bind(Held::positions, holder('p', Held::dem));
    std::vector<float> stashed(5000, 1.5f);
    plan.enter(Stage::shape_index);  // reads the positions
    CHECK(calls == "-d");
    plan.enter(Stage::reeb_events);
    CHECK(calls == "-d-p");
    plan.enter(Stage::reeb_events);  // again: nothing moves
    CHECK(calls == "-d-p");
    plan.stash(stashed);
    CHECK(stashed.empty());
    CHECK(plan.parked_in(Stage::reeb_events) == 5000 * sizeof(float));
    plan.take_back(stashed);
    CHECK(stashed == std::vector<float>(5000, 1.5f));
    // The positions come back from the DEM, which goes again: the flooding does not read it.
    plan.enter(Stage::flood);
    CHECK(calls == "-d-p+d+p-d");
    plan.enter(Stage::regions);
    CHECK(calls == "-d-p+d+p-d+d");
    CHECK_THROWS_WITH(plan.enter(Stage::grow),
                      Catch::Contains("the stage 'grow' entered after 'regions'"));
}

TEST_CASE("Below the least worth parking, the arrays stay in memory", "[core][residency]") {
    const auto dir = terrain::test::scratch_dir("residency_held");
    Arrays arrays;
    ResidencyPlan plan(dir.string(), SIZE_MAX);
    arrays.bind(plan);
    for (const Stage s : {Stage::shape_index, Stage::simplify_arcs, Stage::regions}) {
        plan.enter(s);
        for (std::size_t a = 0; a < arrays.values.size(); ++a) {
            CHECK(plan.resident(Held(a)));
            CHECK(arrays.intact(a));
        }
    }
    CHECK(plan.store().most_parked() == 0);
}
