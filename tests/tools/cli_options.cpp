// The options given by name on the command line (read by terrain/pipeline/options.hpp): the
// one line each bad name gives, and the names run.json records for the choices made.
#include <cpl_json.h>
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/test_support.hpp"

using terrain::test::run_cli;
namespace fs = std::filesystem;

TEST_CASE("a bad option name is refused with one line, status 1, nothing written",
          "[cli][options]") {
    const auto dir = terrain::test::scratch_dir("cli_option_names");
    const auto dem = terrain::test::sample("moon_ldem4_copernicus.tif");
    const auto out = (dir / "out").string();
    const std::string area = " takes an area above 0 in m^2 or with a unit (5km2, 2000m2, 3ha); '";
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{"segment", "--cost", "cheap"},
         "terrain segment: segment: unknown cost 'cheap'; use graph or standard"},
        {{"segment", "--absorbed", "bad"},
         "terrain segment: segment: --absorbed is divide, whole or auto; 'bad' is none of them"},
        {{"segment", "--field", "slope"},
         "terrain segment: field: unknown field 'slope'; use shape-index, sdf or height"},
        {{"segment", "--min-area", "5 furlongs"},
         "terrain segment: segment: --min-area" + area + "5 furlongs' is not one"},
        {{"segment", "--min-area", "AUTO"},
         "terrain segment: segment: --min-area" + area + "AUTO' is not one"},
        {{"segment", "--frame", "sideways"},
         "terrain segment: options: --frame must be body, map or auto, not 'sideways'"},
        {{"segment", "--elevation", "bogus"},
         "terrain segment: options: --elevation must be radius, height or auto, not 'bogus'"},
        {{"segment", "--window", "cube"},
         "terrain segment: options: --window must be disk or ball, not 'cube'"},
        // Of several bad values, the numbers are reported before the names.
        {{"segment", "--persistence", "-1", "--cost", "cheap"},
         "terrain segment: segment: --persistence must be a number >= 0"},
        {{"segment", "--absorbed", "y", "--min-area", "x", "--cost", "cheap"},
         "terrain segment: segment: unknown cost 'cheap'; use graph or standard"},
        {{"sweep", "--cost", "cheap"},
         "terrain sweep: segment: unknown cost 'cheap'; use graph or standard"},
        {{"sweep", "--min-areas", "1km2,x"},
         "terrain sweep: sweep: --min-areas" + area + "x' is not one"},
        {{"mesh", "--frame", "up"},
         "terrain mesh: options: --frame must be body, map or auto, not 'up'"},
        {{"reeb", "--field", "slope"},
         "terrain reeb: field: unknown field 'slope'; use shape-index, sdf or height"},
        {{"field", "--field", "nonsense"},
         "terrain field: field: unknown field 'nonsense'; use shape-index, sdf or height"},
    };
    for (const auto& [options, line] : cases) {
        const auto& command = options.front();
        std::vector<std::string> args = {command, dem, "-q", "-o"};
        args.push_back(command == "mesh"    ? out + ".ply"
                       : command == "reeb"  ? out + ".json"
                       : command == "field" ? out + ".tif"
                                            : out);
        args.insert(args.end(), options.begin() + 1, options.end());
        const auto r = run_cli(args);
        INFO(command << " " << options.back());
        CHECK(r.status == 1);
        CHECK(r.err == line + "\n");
        CHECK_FALSE(fs::exists(args[4]));
    }
}

TEST_CASE("run.json names the values auto chose, and a mesh file reads no --frame",
          "[cli][options]") {
    const auto dir = terrain::test::scratch_dir("cli_option_choices");
    const auto mesh = dir / "box.off";
    {
        std::ofstream off(mesh);
        off << "OFF\n8 12 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
               "3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n"
               "3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n";
    }
    const auto parameters = [&](const std::string& name, std::vector<std::string> options) {
        std::vector<std::string> args = {"segment", mesh.string(),         "-q",
                                         "-o",      (dir / name).string(), "--field",
                                         "height",  "--persistence",       "0"};
        args.insert(args.end(), options.begin(), options.end());
        const auto r = run_cli(args);
        INFO(r.err);
        REQUIRE(r.status == 0);
        CPLJSONDocument run;
        REQUIRE(run.Load((dir / name / "run.json").string()));
        return run.GetRoot().GetObj("parameters");
    };
    // A mesh file: the standard cost and whole nodes; its own frame, whatever --frame says.
    auto p = parameters("auto", {"--frame", "sideways"});
    CHECK(p.GetString("field") == "height");
    CHECK(p.GetString("cost") == "standard");
    CHECK(p.GetString("absorbed") == "whole");
    CHECK(p.GetString("frame") == "file");
    CHECK_FALSE(p.GetObj("min_area").IsValid());
    p = parameters("given", {"--cost", "graph", "--absorbed", "divide", "--min-area", "0.5m2"});
    CHECK(p.GetString("cost") == "graph");
    CHECK(p.GetString("absorbed") == "divide");
    CHECK(p.GetString("min_area") == "0.5m2");
    CHECK(p.GetDouble("min_area_m2") == 0.5);
}
