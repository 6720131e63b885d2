// Outputs after interrupts, failures and earlier killed runs: no temporaries left behind,
// every file of a multi-file format renamed, and no output that overwrites another.
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>

#include <chrono>

#include "hostile_support.hpp"

using Catch::Matchers::Contains;
using namespace terrain::test;

namespace {

// The id of a process that has exited (its own child, reaped).
long dead_pid() {
    const pid_t child = ::fork();
    if (child == 0) ::_exit(0);
    int status = 0;
    ::waitpid(child, &status, 0);
    return child;
}

}  // namespace

TEST_CASE("a Shapefile output with a relative -o has every sidecar renamed",
          "[robustness][outputs]") {
    const auto dir = scratch_dir("outputs_shapefile");
    const std::string cli =
        std::getenv("TERRAIN_TEST_CLI") ? std::getenv("TERRAIN_TEST_CLI") : TERRAIN_CLI;
    const auto r = run_program("sh", {"-c", "cd '" + dir.string() + "' && '" + cli + "' segment '" +
                                                sample("moon_ldem4_copernicus.tif") +
                                                "' -o out --format 'ESRI Shapefile' -q"});
    REQUIRE(r.status == 0);
    for (const char* ext : {".shp", ".shx", ".dbf", ".prj"}) {
        INFO(ext);
        CHECK(std::filesystem::exists(dir / "out" / (std::string("regions") + ext)));
    }
    CHECK(temporaries_in(dir).empty());
}

TEST_CASE("reeb --write-field naming the -o file is refused before writing",
          "[robustness][outputs]") {
    const auto dir = scratch_dir("outputs_same_path");
    const auto out = (dir / "g.json").string();
    const auto r = run_limited(
        {"reeb", sample("mars_hirise_crop.tif"), "-o", out, "--write-field", out, "-q"});
    CHECK(r.status == 2);
    CHECK(line_count(r.err) == 1);
    CHECK_THAT(r.err, Contains("same file"));
    CHECK(std::filesystem::is_empty(dir));
}

TEST_CASE("a run removes the temporaries of dead runs beside its output", "[robustness][outputs]") {
    const auto dir = scratch_dir("outputs_stale");
    const std::string dead = std::to_string(dead_pid());
    const std::string alive = std::to_string(::getpid());
    write_bytes(dir / (".m.tmp" + dead + ".ply"), "a killed run's mesh");
    write_bytes(dir / (".m.tmp" + alive + ".ply"), "a running process's mesh");
    write_bytes(dir / ".other.tmp1x.ply", "not a temporary name");
    std::filesystem::create_directories(dir / (".seg.tmp" + dead) / "inner");
    auto r =
        run_limited({"mesh", sample("mars_hirise_crop.tif"), "-o", (dir / "m.ply").string(), "-q"});
    REQUIRE(r.status == 0);
    CHECK_FALSE(std::filesystem::exists(dir / (".m.tmp" + dead + ".ply")));
    CHECK(std::filesystem::exists(dir / (".m.tmp" + alive + ".ply")));
    CHECK(std::filesystem::exists(dir / ".other.tmp1x.ply"));
    r = run_limited(
        {"segment", sample("mars_hirise_crop.tif"), "-o", (dir / "seg").string(), "-q"});
    REQUIRE(r.status == 0);
    CHECK_FALSE(std::filesystem::exists(dir / (".seg.tmp" + dead)));
}

TEST_CASE("SIGINT and SIGTERM stop a run promptly, remove its temporaries and exit 128+N",
          "[robustness][outputs]") {
    const auto dir = scratch_dir("outputs_signals");
    const std::string cli =
        std::getenv("TERRAIN_TEST_CLI") ? std::getenv("TERRAIN_TEST_CLI") : TERRAIN_CLI;
    // A DEM whose segmentation takes tens of seconds.
    REQUIRE(run_limited({"synth", "-o", (dir / "big.lbl").string(), "--width", "1500", "--height",
                         "1500", "-q"})
                .status == 0);
    for (const auto& [signal, status] : {std::pair{"INT", 130}, std::pair{"TERM", 143}}) {
        INFO(signal);
        const auto out = (dir / (std::string("seg_") + signal)).string();
        const auto t0 = std::chrono::steady_clock::now();
        const auto r =
            run_program("sh", {"-c", "'" + cli + "' segment '" + (dir / "big.lbl").string() +
                                         "' -o '" + out + "' -q & p=$!; sleep 2; kill -" + signal +
                                         " $p; wait $p; echo status=$?"});
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        CHECK_THAT(r.out, Contains("status=" + std::to_string(status)));
        CHECK(seconds < 12);
        CHECK_FALSE(std::filesystem::exists(out));
        CHECK(temporaries_in(dir).empty());
    }
}
