#include "hostile_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace terrain::test {

CliResult run_limited(const std::vector<std::string>& args, int seconds, int memory_mb) {
    const char* override_cli = std::getenv("TERRAIN_TEST_CLI");
#ifdef TERRAIN_SANITIZE
    // AddressSanitizer reserves terabytes of address space for its shadow memory, so an
    // address-space limit stops it at start: its own resident-memory limit bounds the run.
    std::vector<std::string> all = {
        "-s",
        "KILL",
        std::to_string(seconds),
        "env",
        "ASAN_OPTIONS=detect_leaks=0:hard_rss_limit_mb=" + std::to_string(memory_mb),
        override_cli ? override_cli : TERRAIN_CLI};
#else
    std::vector<std::string> all = {"-s",
                                    "KILL",
                                    std::to_string(seconds),
                                    "prlimit",
                                    "--as=" + std::to_string(std::int64_t(memory_mb) << 20),
                                    override_cli ? override_cli : TERRAIN_CLI};
#endif
    all.insert(all.end(), args.begin(), args.end());
    return run_program("timeout", all);
}

std::string case_path(const std::string& name) {
    return std::string(TERRAIN_SOURCE_DIR) + "/tests/robustness/cases/" + name;
}

std::string write_bytes(const std::filesystem::path& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out << bytes;
    if (!out) throw std::runtime_error("cannot write " + path.string());
    return path.string();
}

std::vector<std::string> temporaries_in(const std::filesystem::path& dir) {
    std::vector<std::string> out;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(dir))
        if (entry.path().filename().string().find(".tmp") != std::string::npos)
            out.push_back(entry.path().string());
    return out;
}

std::string edited_vesta_label(const std::filesystem::path& dir, const std::string& name,
                               const std::string& from, const std::string& to) {
    std::string label = file_bytes(sample("vesta_hamo_tile.lbl"));
    const auto at = label.find(from);
    if (at == std::string::npos) throw std::runtime_error("'" + from + "' not in the label");
    label.replace(at, from.size(), to);
    std::filesystem::copy_file(sample("vesta_hamo_tile.img"), dir / "vesta_hamo_tile.img",
                               std::filesystem::copy_options::overwrite_existing);
    return write_bytes(dir / name, label);
}

std::size_t line_count(const std::string& text) {
    return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

void check_refused(const std::string& input, const std::filesystem::path& dir,
                   const std::vector<std::string>& expected, int seconds) {
    const std::vector<std::vector<std::string>> commands = {
        {"info", input},
        {"mesh", input, "-o", (dir / "m.ply").string(), "-q"},
        {"segment", input, "-o", (dir / "seg").string(), "-q"}};
    for (const auto& args : commands) {
        INFO(args[0] << " " << input);
        const auto r = run_limited(args, seconds, 2048);
        INFO(r.err);
        CHECK(r.status == 1);
        CHECK(line_count(r.err) == 1);
        for (const auto& text : expected) CHECK_THAT(r.err, Catch::Matchers::Contains(text));
        CHECK_THAT(r.err, !Catch::Matchers::Contains("divide_absorbed"));
        CHECK(r.out.find("nan") == std::string::npos);
    }
    CHECK_FALSE(std::filesystem::exists(dir / "m.ply"));
    CHECK_FALSE(std::filesystem::exists(dir / "seg"));
}

}  // namespace terrain::test
