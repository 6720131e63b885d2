// Option values outside their documented ranges exit 1 with one line, quickly; bad usage
// (unknown option, missing argument) exits 2.
#include <catch2/catch.hpp>

#include "hostile_support.hpp"

using Catch::Matchers::Contains;
using namespace terrain::test;

TEST_CASE("field options outside their ranges exit 1 before any work", "[robustness][cli]") {
    const auto dir = scratch_dir("limits_field");
    const auto input = sample("mars_hirise_crop.tif");
    const std::vector<std::vector<std::string>> bad = {
        {"--rings", "0"},       {"--rings", "11"},        {"--rings", "1000"},
        {"--rays", "0"},        {"--rays", "1001"},       {"--rays", "100000000"},
        {"--radius", "-1"},     {"--radius", "1e9"},      {"--cone-angle", "200"},
        {"--pixel-size", "-1"}, {"--elevation", "bogus"}, {"--frame", "bogus"},
        {"--rings", "abc"},     {"--max-memory", "-5G"},
    };
    for (const auto& option : bad) {
        std::vector<std::string> args = {"field", input,        "-o", (dir / "f.tif").string(),
                                         "-q",    "--overwrite"};
        if (option[0] == "--rays" || option[0] == "--cone-angle") {
            args.insert(args.end(), {"--field", "sdf", "--allow-open"});
        }
        args.insert(args.end(), option.begin(), option.end());
        INFO(option[0] << " " << option[1]);
        const auto r = run_limited(args, 30);
        CHECK(r.status == 1);
        CHECK(line_count(r.err) == 1);
        CHECK_FALSE(std::filesystem::exists(dir / "f.tif"));
    }
}

TEST_CASE("bad values exit 1 and bad usage exits 2 in every command", "[robustness][cli]") {
    const auto dir = scratch_dir("limits_exit_codes");
    const auto dem = sample("mars_hirise_crop.tif");
    const auto json = (dir / "g.json").string();
    // Bad values: 1.
    CHECK(run_limited({"reeb", dem, "-o", json, "-q", "--algorithm", "bogus"}).status == 1);
    CHECK(run_limited({"reeb", dem, "-o", json, "-q", "--persistence", "-1"}).status == 1);
    CHECK(run_limited({"info", dem, "--pixel-size", "-1"}).status == 1);
    CHECK(run_limited({"info", dem, "--band", "7"}).status == 1);
    // Bad usage: 2.
    for (const char* command : {"info", "mesh", "field", "reeb", "segment", "sweep"}) {
        INFO(command);
        CHECK(run_limited({command, dem, "--no-such-option"}).status == 2);
        CHECK(run_limited({command, dem, "-o"}).status == 2);  // missing argument
    }
}

TEST_CASE("segment and sweep check --radius alike", "[robustness][cli]") {
    // The disk window costs the same at any radius: 3 km (43 pixels of the Vesta sample, over
    // 20 mean edge lengths) runs in both; one wider than the grid is refused by both.
    const auto dir = scratch_dir("limits_radius");
    const auto dem = sample("vesta_hamo_tile.lbl");
    for (const char* command : {"segment", "sweep"}) {
        INFO(command);
        std::vector<std::string> args = {
            command, dem,           "-o",           (dir / command).string(),
            "-q",    "--overwrite", "--area-ratio", "0.5"};
        if (std::string(command) == "sweep")
            args.back() = "0.5", args[args.size() - 2] = "--area-ratios";
        auto wide = args;
        wide.insert(wide.end(), {"--radius", "3000"});
        CHECK(run_limited(wide, 120).status == 0);
        auto huge = args;
        huge.insert(huge.end(), {"--radius", "1e7"});
        const auto r = run_limited(huge, 30);
        CHECK(r.status == 1);
        CHECK(line_count(r.err) == 1);
        CHECK_THAT(r.err, Contains("wider than the grid"));
    }
}
