#include <catch2/catch.hpp>

#include <vector>

#include "terrain/core/error.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/synth/crater_field.hpp"

using namespace terrain;

namespace {

// A callback that records every fraction and asks to stop once one reaches `stop_at`.
struct Recorder {
    std::vector<double> fractions;
    double stop_at = 2.0;
    ProgressFn fn() {
        return [this](double fraction, std::string_view) {
            fractions.push_back(fraction);
            return fraction < stop_at;
        };
    }
};

synth::VestaTileOptions small_tile() {
    synth::VestaTileOptions o;
    o.width = o.height = 64;
    return o;
}

}  // namespace

TEST_CASE("report_progress passes the fraction clamped to [0,1] and the message", "[progress]") {
    std::vector<std::pair<double, std::string>> calls;
    const ProgressFn fn = [&](double fraction, std::string_view message) {
        calls.emplace_back(fraction, std::string(message));
        return true;
    };
    report_progress(fn, 0.25, "mesh");
    report_progress(fn, -0.5);
    report_progress(fn, 1.5, "done");
    REQUIRE(calls.size() == 3);
    CHECK(calls[0] == std::pair<double, std::string>{0.25, "mesh"});
    CHECK(calls[1] == std::pair<double, std::string>{0.0, ""});
    CHECK(calls[2] == std::pair<double, std::string>{1.0, "done"});
    CHECK_NOTHROW(report_progress(ProgressFn{}, 0.5, "nobody listens"));
}

TEST_CASE("a callback returning false cancels with a 'progress' error", "[progress]") {
    const ProgressFn stop = [](double, std::string_view) { return false; };
    try {
        report_progress(stop, 0.5, "sdf");
        FAIL("report_progress did not throw");
    } catch (const Error& e) {
        CHECK(e.stage() == "progress");
    }
}

TEST_CASE("scaled_progress maps a sub-task's [0,1] onto the parent's slice", "[progress]") {
    Recorder parent;
    const auto sub = scaled_progress(parent.fn(), 0.2, 0.6);
    REQUIRE(sub);
    for (double f : {0.0, 0.5, 1.0, -1.0, 3.0}) report_progress(sub, f);
    REQUIRE(parent.fractions.size() == 5);
    CHECK(parent.fractions[0] == Approx(0.2));
    CHECK(parent.fractions[1] == Approx(0.4));
    CHECK(parent.fractions[2] == Approx(0.6));
    CHECK(parent.fractions[3] == Approx(0.2));  // clamped to the slice
    CHECK(parent.fractions[4] == Approx(0.6));

    // Slices of slices compose: [0.5,1] of [0.2,0.6] is [0.4,0.6].
    parent.fractions.clear();
    report_progress(scaled_progress(sub, 0.5, 1.0), 0.5);
    REQUIRE(parent.fractions.size() == 1);
    CHECK(parent.fractions[0] == Approx(0.5));

    // No parent, no callback: the sub-task reports to nobody.
    CHECK_FALSE(scaled_progress(ProgressFn{}, 0.0, 0.5));
}

TEST_CASE("a library stage reports non-decreasing fractions up to 1 and can be cancelled",
          "[progress]") {
    Recorder whole;
    synth::generate_vesta_tile(small_tile(), scaled_progress(whole.fn(), 0.3, 0.8));
    REQUIRE(whole.fractions.size() >= 3);
    CHECK(whole.fractions.front() == Approx(0.3));
    CHECK(whole.fractions.back() == Approx(0.8));
    for (std::size_t i = 1; i < whole.fractions.size(); ++i) {
        INFO("report " << i);
        CHECK(whole.fractions[i] >= whole.fractions[i - 1]);
        CHECK(whole.fractions[i] <= 0.8);
    }

    // Cancelled halfway: the stage stops at the next report with the "progress" error.
    Recorder cancelling;
    cancelling.stop_at = 0.5;
    try {
        synth::generate_vesta_tile(small_tile(), cancelling.fn());
        FAIL("the tile was finished despite the cancellation");
    } catch (const Error& e) {
        CHECK(e.stage() == "progress");
    }
    REQUIRE_FALSE(cancelling.fractions.empty());
    CHECK(cancelling.fractions.back() >= 0.5);
    CHECK(cancelling.fractions.back() < 1.0);
}
