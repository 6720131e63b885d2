#pragma once
// Hostile inputs for the robustness tests: the `terrain` CLI run under a time and memory
// limit (a hang or a blow-up fails the test instead of the machine), and the small files
// that crashed, hung or exhausted memory, recreated byte for byte.

#include <filesystem>
#include <string>
#include <vector>

#include "support/test_support.hpp"

namespace terrain::test {

// `terrain args...` killed after `seconds` and limited to `memory_mb` of address space.
// TERRAIN_TEST_CLI in the environment replaces the binary (to replay the cases on another
// build).
CliResult run_limited(const std::vector<std::string>& args, int seconds = 60, int memory_mb = 3072);

// The path of an input a fuzz target found, kept in tests/robustness/cases.
std::string case_path(const std::string& name);

// Writes `bytes` to `path`; returns the path.
std::string write_bytes(const std::filesystem::path& path, const std::string& bytes);

// Files in `dir` whose name contains ".tmp" (temporaries of atomic outputs).
std::vector<std::string> temporaries_in(const std::filesystem::path& dir);

// A copy of the Vesta sample label in `dir` under `name`, with `from` replaced by `to`
// (once); the image is copied beside it.
std::string edited_vesta_label(const std::filesystem::path& dir, const std::string& name,
                               const std::string& from, const std::string& to);

std::size_t line_count(const std::string& text);

// info, mesh and segment on `input` each exit 1 within `seconds` with one line holding every
// `expected` (never the name of an internal step such as divide_absorbed, no "nan" printed),
// and write nothing into `dir`.
void check_refused(const std::string& input, const std::filesystem::path& dir,
                   const std::vector<std::string>& expected, int seconds = 60);

}  // namespace terrain::test
