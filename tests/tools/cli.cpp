// The `terrain` command line as users and scripts see it: exit codes, one-line errors, output.
#include <cpl_json.h>
#include <catch2/catch.hpp>

#include <algorithm>
#include <fstream>

#include "support/test_support.hpp"

using Catch::Matchers::Contains;
using terrain::test::run_cli;

namespace {
std::size_t line_count(const std::string& s) {
    return std::count(s.begin(), s.end(), '\n');
}
}  // namespace

TEST_CASE("terrain --version names terrain and its libraries", "[cli]") {
    const auto r = run_cli({"--version"});
    CHECK(r.status == 0);
    for (const char* name : {"terrain 0.", "GDAL", "PROJ", "CGAL", "GeographicLib", "FreeType"})
        CHECK_THAT(r.out, Contains(name));
}

TEST_CASE("terrain usage errors exit 2", "[cli]") {
    CHECK(run_cli({}).status == 2);
    CHECK(run_cli({"no-such-command"}).status == 2);
    const auto r = run_cli({"info", "--no-such-option", "x.tif"});
    CHECK(r.status == 2);
    CHECK(line_count(r.err) == 1);
    CHECK(run_cli({"info"}).status == 2);  // the DEM is required
    CHECK(run_cli({"info", "--help"}).status == 0);
}

TEST_CASE("terrain info --json on LDEM_4", "[cli][real_data]") {
    const auto path = terrain::test::real_data("moon_lola_ldem4/LDEM_4.LBL");
    REQUIRE(path.has_value());
    const auto r = run_cli({"info", *path, "--json"});
    REQUIRE(r.status == 0);
    CPLJSONDocument doc;
    REQUIRE(doc.LoadMemory(r.out));
    const auto root = doc.GetRoot();
    CHECK(root.GetString("body/name") == "Moon");
    CHECK(root.GetDouble("body/semi_major_axis") == 1737400);
    CHECK(root.GetString("elevation/kind") == "radius");
    CHECK(root.GetArray("pixel_size_m")[0].ToDouble() == Approx(7581).margin(1));
    CHECK(root.GetBool("extent/global_longitude"));
    CHECK(root.GetArray("size")[0].ToInteger() == 1440);
}

TEST_CASE("terrain info text on every sample names its body", "[cli]") {
    const std::pair<const char*, const char*> cases[] = {
        {"vesta_hamo_tile.lbl", "Vesta"},
        {"moon_ldem4_copernicus.tif", "Moon"},
        {"moon_ldem1_global.tif", "global in longitude"},
        {"mars_hirise_crop.tif", "local metric grid"},
    };
    for (const auto& [file, expected] : cases) {
        const auto r = run_cli({"info", terrain::test::sample(file)});
        INFO(file << ": " << r.err);
        CHECK(r.status == 0);
        CHECK_THAT(r.out, Contains(expected));
    }
}

TEST_CASE("terrain info on bad input: one line, exit 1", "[cli][bad_input]") {
    const auto dir = terrain::test::scratch_dir("cli_bad");
    std::ofstream(dir / "text.tif") << "not a raster\n";
    terrain::test::RasterSpec one;
    one.width = one.height = 1;
    terrain::test::RasterSpec nodata;
    nodata.nodata = 0;
    terrain::test::RasterSpec nan;
    nan.values.assign(16, 1.0);
    nan.values[3] = std::numeric_limits<double>::quiet_NaN();
    const std::vector<std::vector<std::string>> cases = {
        {"info", (dir / "missing.tif").string()},
        {"info", (dir / "text.tif").string()},
        {"info", terrain::test::write_raster(dir / "one.tif", one)},
        {"info", terrain::test::write_raster(dir / "nodata.tif", nodata)},
        {"info", terrain::test::write_raster(dir / "nan.tif", nan)},
        {"info", terrain::test::sample("mars_hirise_crop.tif"), "--band", "3"},
        {"info", terrain::test::sample("mars_hirise_crop.tif"), "--elevation", "radius"},
    };
    for (const auto& args : cases) {
        const auto r = run_cli(args);
        INFO(args[1] << " -> " << r.err);
        CHECK(r.status == 1);
        CHECK(line_count(r.err) == 1);
        CHECK_THAT(r.err, Contains("terrain info: read: "));
        CHECK(r.out.empty());
    }
}
