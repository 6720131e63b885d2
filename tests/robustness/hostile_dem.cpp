// Rasters that hung, exhausted memory or gave silent garbage (exit 0 with inf or NaN areas):
// each is now refused with one line naming the problem, or read in bounded memory.
#include <gdal_priv.h>

#include <catch2/catch.hpp>

#include <sys/resource.h>

#include <cmath>
#include <memory>
#include <string>

#include "hostile_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/read_dem.hpp"

using Catch::Matchers::Contains;
using namespace terrain::test;

namespace {

std::vector<double> ramp(int n) {
    std::vector<double> v(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = i % 7;
    return v;
}

}  // namespace

TEST_CASE("absurd pixel sizes are refused before anything loops", "[robustness][dem]") {
    const auto dir = scratch_dir("hostile_pixel_size");
    // 1e19 degrees hung info, mesh and segment; 1e10 took 7.7 s.
    for (double size : {1e19, 1e10}) {
        RasterSpec spec;
        spec.width = spec.height = 8;
        spec.values = ramp(64);
        spec.crs = "EPSG:4326";
        spec.geotransform = {0, size, 0, 0, 0, -size};
        check_refused(write_raster(dir / "huge_degrees.tif", spec), dir, {"degrees"}, 30);
    }
    // A PDS label with MAP_SCALE = 1e30 <KM/PIXEL> hung the same way.
    const auto huge = edited_vesta_label(dir, "scale1e30.lbl", "0.06954046238414907", "1e30");
    check_refused(huge, dir, {"half the circumference of Vesta"}, 30);
    // MAP_SCALE = 0: pixels of no area gave an area of 0 and one flat region.
    const auto zero = edited_vesta_label(dir, "scale0.lbl", "0.06954046238414907", "0");
    check_refused(zero, dir, {"degenerate geotransform"}, 30);
}

TEST_CASE("geographic grids beyond the poles are refused", "[robustness][dem]") {
    const auto dir = scratch_dir("hostile_latitudes");
    RasterSpec spec;
    spec.width = spec.height = 8;
    spec.values = ramp(64);
    spec.crs = "EPSG:4326";
    spec.geotransform = {0, 10, 0, 95, 0, -80};  // latitudes 95 to -545: "the seam closes"
    check_refused(write_raster(dir / "poles.tif", spec), dir, {"inside +-90"}, 30);
}

TEST_CASE("values are checked after scale and offset", "[robustness][dem]") {
    const auto dir = scratch_dir("hostile_values");
    RasterSpec scaled;
    scaled.width = scaled.height = 8;
    scaled.values = ramp(64);
    for (auto& v : scaled.values) v += 1;
    scaled.scale = 1e308;  // values inf, area -nan, one region
    check_refused(write_raster(dir / "scale.tif", scaled), dir, {"after scale and offset"}, 30);

    RasterSpec huge;
    huge.width = huge.height = 8;
    huge.type = "Float64";
    huge.values = ramp(64);
    huge.values[27] = 1e300;
    huge.values[28] = -1e300;
    check_refused(write_raster(dir / "e300.tif", huge), dir, {"not a surface"}, 30);

    RasterSpec one;
    one.width = one.height = 8;
    one.values = ramp(64);
    one.values[18] = 1e30;
    check_refused(write_raster(dir / "e30.tif", one), dir, {"not a surface"}, 30);
}

TEST_CASE("a sparse 20000x20000 GeoTIFF is described in bounded memory", "[robustness][dem]") {
    const auto dir = scratch_dir("hostile_sparse");
    const std::string path = (dir / "sparse.tif").string();
    {
        GDALAllRegister();
        const char* options[] = {"SPARSE_OK=TRUE", "TILED=YES", nullptr};
        std::unique_ptr<GDALDataset> ds(GetGDALDriverManager()->GetDriverByName("GTiff")->Create(
            path.c_str(), 20000, 20000, 1, GDT_Float32, const_cast<char**>(options)));
        REQUIRE(ds);
        double gt[6] = {0, 1, 0, 0, 0, -1};
        ds->SetGeoTransform(gt);
    }
    REQUIRE(std::filesystem::file_size(path) < 100000);
    // info cost 3.47 GB; 700 MB of address space here.
    const auto info = run_limited({"info", path}, 60, 700);
    CHECK(info.status == 0);
    CHECK_THAT(info.out, Contains("400000000 valid"));
    // The mesh of 4e8 pixels would need far more than the machine has: refused up front.
    const auto mesh = run_limited({"mesh", path, "-o", (dir / "m.ply").string(), "-q"}, 30, 700);
    CHECK(mesh.status == 1);
    CHECK(line_count(mesh.err) == 1);
    CHECK_THAT(mesh.err, Contains("needs about"));
}

TEST_CASE("a PDS label declaring more than its image holds is one line, fast",
          "[robustness][dem]") {
    const auto dir = scratch_dir("hostile_pds_size");
    const auto label =
        edited_vesta_label(dir, "claim.lbl", "LINES                      = 512", "LINES = 20000");
    std::string text = file_bytes(label);
    const std::string samples = "LINE_SAMPLES               = 512";
    const auto at = text.find(samples);
    REQUIRE(at != std::string::npos);
    text.replace(at, samples.size(), "LINE_SAMPLES = 20000");
    // Pixels of 1 m, so that the 20000 rows stay on Vesta (at 64 pixels a degree they span
    // 312 degrees of latitude, refused before the size is checked).
    const std::string scale = "0.06954046238414907 <KM/PIXEL>";
    const auto scale_at = text.find(scale);
    REQUIRE(scale_at != std::string::npos);
    text.replace(scale_at, scale.size(), "0.001 <KM/PIXEL>");
    write_bytes(label, text);
    // It cost 3.18 GB before "cannot read row 6".
    const auto r = run_limited({"info", label}, 30, 700);
    CHECK(r.status == 1);
    CHECK(line_count(r.err) == 1);
    CHECK_THAT(r.err, Contains("declares 20000x20000 pixels"));
}

TEST_CASE("a PDS label pointing to a missing image is one line", "[robustness][dem]") {
    const auto dir = scratch_dir("hostile_pds_missing");
    const auto label =
        edited_vesta_label(dir, "missing.lbl", "\"vesta_hamo_tile.img\"", "\"missing.img\"");
    const auto r = run_limited({"info", label}, 30);
    CHECK(r.status == 1);
    CHECK(line_count(r.err) == 1);
    CHECK_THAT(r.err, Contains("missing.img"));
}

TEST_CASE("a limit given with --max-memory refuses work over it with one line",
          "[robustness][dem]") {
    const auto dir = scratch_dir("max_memory");
    const auto input = sample("vesta_hamo_tile.lbl");
    auto r = run_limited({"mesh", input, "-o", (dir / "m.ply").string(), "--max-memory", "1M"});
    CHECK(r.status == 1);
    CHECK(line_count(r.err) == 1);
    CHECK_THAT(r.err, Contains("but the memory limit is 1 MB (1048576 bytes)"));
    CHECK_FALSE(std::filesystem::exists(dir / "m.ply"));
    r = run_limited({"mesh", input, "-o", (dir / "m.ply").string(), "--max-memory", "lots"});
    CHECK(r.status == 1);
    r = run_limited({"mesh", input, "-o", (dir / "m.ply").string(), "--max-memory", "1G", "-q"});
    CHECK(r.status == 0);
    CHECK(std::filesystem::exists(dir / "m.ply"));
}

TEST_CASE("a truncated ASCII grid is refused at once instead of rereading its lines",
          "[robustness][dem]") {
    // Found by fuzz_dem: GDAL's AAIGrid driver finds a line by reading every line before it,
    // again for each one that failed, so asking first for the last row of a grid whose text
    // ends early took time exponential in the missing lines (40 rows: hours).
    const auto dir = scratch_dir("hostile_ascii_grid");
    std::string text = "ncols 16\nnrows 40\nxllcorner 0\nyllcorner 0\ncellsize 10\n";
    // Three rows of long values: the text could hold the 640 values, the rows after are missing.
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 16; ++c) text += std::to_string(100 + c) + ".000000000000000000000000 ";
        text += "\n";
    }
    const auto truncated = write_bytes(dir / "truncated.asc", text);
    for (const char* command : {"info", "mesh"}) {
        std::vector<std::string> args = {command, truncated};
        if (std::string(command) == "mesh")
            args.insert(args.end(), {"-o", (dir / "m.ply").string(), "-q"});
        const auto r = run_limited(args, 30);
        INFO(command);
        CHECK(r.status == 1);
        CHECK(line_count(r.err) == 1);
        CHECK_THAT(r.err, Contains("row 3"));
    }
    // A header declaring more values than its text can hold (each takes two characters).
    const auto huge = write_bytes(dir / "huge.asc",
                                  "ncols 20000\nnrows 20000\nxllcorner 0\n"
                                  "yllcorner 0\ncellsize 10\n1 2 3 4\n");
    const auto r = run_limited({"info", huge}, 30);
    CHECK(r.status == 1);
    CHECK(line_count(r.err) == 1);
    CHECK_THAT(r.err, Contains("text holds at most"));
    CHECK_FALSE(std::filesystem::exists(dir / "m.ply"));
}

TEST_CASE("a GeoTIFF whose one row of blocks is larger than memory is refused",
          "[robustness][dem]") {
    // Found by fuzz_dem: 505 bytes declaring 65 304 x 24 pixel-interleaved pixels of 63 487
    // Int16 bands. Reading one row of band 1 makes GDAL allocate the whole interleaved block,
    // 8.3 GB, which the budget (one band) did not count.
    const auto dir = scratch_dir("hostile_interleaved");
    const std::string input = case_path("dem_pixel_interleaved_63487_bands.tif");
    for (const char* command : {"info", "mesh"}) {
        std::vector<std::string> args = {command, input};
        if (std::string(command) == "mesh")
            args.insert(args.end(), {"-o", (dir / "m.ply").string(), "-q"});
        const auto r = run_limited(args, 30, 2048);
        INFO(command);
        CHECK(r.status == 1);
        CHECK(line_count(r.err) == 1);
        CHECK_THAT(r.err, Contains("block"));
    }
    CHECK_FALSE(std::filesystem::exists(dir / "m.ply"));
}

TEST_CASE("read_dem's memory follows the rows it reads, not the size a header declares",
          "[robustness][dem]") {
    // Found by fuzz_dem: 826 bytes declaring 18464 x 65504 Byte pixels (1.2 G) whose first
    // strip cannot be read. read_dem filled its 9.7 GB value array with NaN before reading
    // row 0 (the budget allowed it on a machine with that much free memory); the command
    // line was safe (`info` reads rows only, `mesh` refuses the 203 GB plan), the library
    // was not.
    const std::string input = case_path("dem_826_bytes_declaring_1g_pixels.tif");
    rusage before{};
    getrusage(RUSAGE_SELF, &before);
    try {
        (void)terrain::io::read_dem(input);
        FAIL("read_dem accepted it");
    } catch (const terrain::Error& e) {
        // "cannot read row 0", or on a machine with less free memory the budget's refusal.
        const std::string what = e.what();
        CHECK((what.find("cannot read row 0") != std::string::npos ||
               what.find("needs about") != std::string::npos));
    }
    rusage after{};
    getrusage(RUSAGE_SELF, &after);
    const double grown_mb = double(after.ru_maxrss - before.ru_maxrss) / 1024.0;  // KB
    INFO("peak resident set grew by " << grown_mb << " MB");
    CHECK(grown_mb < 200);
}
