// Arrays parked on disk while the Reeb graph and the simplification run
// (libterrain/src/pipeline/parked_arrays.hpp): the same bytes back, nothing left behind, and a
// file that cannot be written leaves them in memory.
#include <signal.h>
#include <sys/resource.h>

#include <catch2/catch.hpp>

#include <cstdint>
#include <filesystem>
#include <numeric>
#include <vector>

#include "../../libterrain/src/pipeline/parked_arrays.hpp"
#include "support/test_support.hpp"

namespace fs = std::filesystem;
using terrain::pipeline::internal::ParkedArrays;

namespace {

std::size_t files_in(const fs::path& dir) {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), {}));
}

}  // namespace

TEST_CASE("Parked arrays come back the same and leave no file", "[pipeline][park]") {
    const auto dir = terrain::test::scratch_dir("parked_arrays");
    std::vector<std::int32_t> a(300000);
    std::iota(a.begin(), a.end(), -7);
    std::vector<float> b(123457, 0.25f);
    b[77] = -3.5f;
    std::vector<std::uint8_t> c(5, 9);
    const auto a0 = a;
    const auto b0 = b;
    const auto c0 = c;
    std::vector<double> seen;
    const auto progress = [&](double f, std::string_view) {
        seen.push_back(f);
        return true;
    };
    {
        ParkedArrays parked(dir.string(), 1000);
        parked.decide(999);  // below the minimum: nothing is parked
        CHECK_FALSE(parked.on());
        CHECK_FALSE(parked.park(a, progress, 0, 1));
        CHECK(a == a0);
        parked.decide(1000);
        REQUIRE(parked.on());
        CHECK(files_in(dir) == 0);  // the file has no name
        CHECK(parked.park(a, progress, 0, 0.5));
        CHECK(parked.park(b, progress, 0.5, 0.9));
        CHECK(parked.park(c, progress, 0.9, 1));
        CHECK(a.capacity() == 0);
        CHECK(b.capacity() == 0);
        CHECK(parked.parked_bytes() == a0.size() * 4 + b0.size() * 4 + c0.size());
        // Read back in another order.
        parked.restore(b, progress, 0, 1);
        parked.restore(c, progress, 0, 1);
        parked.restore(a, progress, 0, 1);
        CHECK(a == a0);
        CHECK(b == b0);
        CHECK(c == c0);
        CHECK(parked.parked_bytes() == 0);
        std::vector<int> never;
        parked.restore(never, progress, 0, 1);  // not parked: nothing happens
        CHECK(never.empty());
    }
    CHECK(files_in(dir) == 0);
    CHECK_FALSE(seen.empty());
    // A directory that does not exist: nothing is parked, the arrays stay.
    ParkedArrays nowhere((dir / "missing").string(), 0);
    nowhere.decide(100);
    CHECK_FALSE(nowhere.on());
    CHECK_FALSE(nowhere.park(a, progress, 0, 1));
    CHECK(a == a0);
}

TEST_CASE("Parked arrays read back give their disk back, and the next ones reuse it",
          "[pipeline][park]") {
    const auto dir = terrain::test::scratch_dir("parked_arrays_reuse");
    std::vector<std::int32_t> a(300000), b(200000), c(150000);
    std::iota(a.begin(), a.end(), 1);
    std::iota(b.begin(), b.end(), -500000);
    std::iota(c.begin(), c.end(), 77);
    const auto a0 = a, b0 = b, c0 = c;
    const std::size_t ab = (a.size() + b.size()) * 4, bb = b.size() * 4, cb = c.size() * 4;
    constexpr std::size_t kBlock = 4096;  // (a file system's block: each array may take parts of
                                          // two more)
    ParkedArrays parked(dir.string(), 0);
    parked.decide(1);
    REQUIRE(parked.on());
    CHECK(parked.disk_bytes() == 0);
    REQUIRE(parked.park(a, {}, 0, 1));
    REQUIRE(parked.park(b, {}, 0, 1));
    CHECK(parked.file_peak() == ab);
    CHECK(parked.disk_bytes() >= ab);
    // a read back: its bytes go back to the disk (a hole before b), b's stay.
    parked.restore(a, {}, 0, 1);
    CHECK(a == a0);
    CHECK(parked.disk_bytes() >= bb);
    CHECK(parked.disk_bytes() <= bb + 2 * kBlock);
    // c fits in a's place: the file grows no longer.
    REQUIRE(parked.park(c, {}, 0, 1));
    CHECK(parked.file_peak() == ab);
    CHECK(parked.disk_bytes() <= bb + cb + 4 * kBlock);
    // a again does not fit before b any more: after it.
    REQUIRE(parked.park(a, {}, 0, 1));
    CHECK(parked.file_peak() == ab + a0.size() * 4);
    parked.restore(b, {}, 0, 1);
    parked.restore(a, {}, 0, 1);  // the last one: the file is cut after c
    CHECK(parked.disk_bytes() <= cb + kBlock);
    parked.restore(c, {}, 0, 1);
    CHECK(a == a0);
    CHECK(b == b0);
    CHECK(c == c0);
    CHECK(parked.parked_bytes() == 0);
    CHECK(parked.disk_bytes() == 0);
}

TEST_CASE("A file that cannot grow leaves the arrays in memory, those parked come back",
          "[pipeline][park]") {
    // A full disk, played by a file size limit (the write fails with EFBIG; SIGXFSZ ignored).
    const auto dir = terrain::test::scratch_dir("parked_arrays_full");
    std::vector<std::int32_t> small(1000, 5), large(400000, 6);
    const auto small0 = small, large0 = large;
    struct rlimit old {};
    REQUIRE(getrlimit(RLIMIT_FSIZE, &old) == 0);
    const auto old_handler = signal(SIGXFSZ, SIG_IGN);
    struct rlimit limit = old;
    limit.rlim_cur = 1 << 20;  // 1 MiB: the small array fits, the large one does not
    REQUIRE(setrlimit(RLIMIT_FSIZE, &limit) == 0);
    {
        ParkedArrays parked(dir.string(), 0);
        parked.decide(1);
        REQUIRE(parked.on());
        CHECK(parked.park(small, {}, 0, 1));
        CHECK_FALSE(parked.park(large, {}, 0, 1));
        CHECK(large == large0);    // kept in memory
        CHECK_FALSE(parked.on());  // and nothing more is parked
        parked.restore(small, {}, 0, 1);
        CHECK(small == small0);
    }
    setrlimit(RLIMIT_FSIZE, &old);
    signal(SIGXFSZ, old_handler);
}
