#pragma once
// Helpers for the tests: sample data paths, a scratch directory, small rasters made with GDAL,
// and running the `terrain` CLI.

#include <tbb/global_control.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace terrain::test {

// examples/data/<name>
std::string sample(const std::string& name);
// tests/data/<relative>: the real DEMs the tests read (tests/data/README.md), or nullopt when
// the file is missing.
std::optional<std::string> real_data(const std::string& relative);

// A fresh, empty directory under the build tree for one test (removed at the start of the
// next run, kept for inspection after a failure).
std::filesystem::path scratch_dir(const std::string& name);

// The whole content of a file, as bytes.
std::string file_bytes(const std::filesystem::path& path);

// The bytes of the pages overlapping [p, p + n) that are resident now (mincore).
std::size_t resident_bytes(const void* p, std::size_t n);

struct RasterSpec {
    int width = 4, height = 4;
    std::string type = "Float32";  // a GDAL data type name
    std::vector<double> values;    // row-major, width*height
    std::optional<double> nodata;
    std::string crs;                   // empty: none; else anything SetFromUserInput takes
    std::vector<double> geotransform;  // empty: none
    double scale = 1, offset = 0;
};
// Writes a GeoTIFF with GDAL; returns its path.
std::string write_raster(const std::filesystem::path& path, const RasterSpec& spec);

// Band 1 of a raster read with GDAL as floats, row-major.
std::vector<float> read_raster_values(const std::string& path);

// The result of `f()` with TBB limited to `threads` threads.
template <class F>
auto with_threads(int threads, F&& f) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    return f();
}

struct CliResult {
    int status = -1;
    std::string out, err;
};
// Runs the built `terrain` binary with arguments (shell-quoted), capturing stdout and stderr.
CliResult run_cli(const std::vector<std::string>& args);
// The same with another program, and NAME=value settings for its environment.
CliResult run_program(const std::string& program, const std::vector<std::string>& args,
                      const std::vector<std::string>& environment = {});

}  // namespace terrain::test
