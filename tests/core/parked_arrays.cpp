// Arrays parked on disk while the Reeb graph and the simplification run
// (terrain/internal/core/parked_arrays.hpp): the same bytes back, nothing left behind, and a
// file that cannot be written leaves them in memory.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <catch2/catch.hpp>

#include <cstdint>
#include <filesystem>
#include <numeric>
#include <vector>

#include "support/test_support.hpp"
#include "terrain/internal/core/parked_arrays.hpp"

namespace fs = std::filesystem;
using terrain::detail::ParkedArrays;

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
    // Each array starts on a block: the file's length counts the last block of each in full.
    const auto up = [&](std::size_t bytes) { return (bytes + kBlock - 1) / kBlock * kBlock; };
    const std::size_t ab_file = up(a.size() * 4) + up(bb);
    ParkedArrays parked(dir.string(), 0);
    parked.decide(1);
    REQUIRE(parked.on());
    CHECK(parked.disk_bytes() == 0);
    REQUIRE(parked.park(a, {}, 0, 1));
    REQUIRE(parked.park(b, {}, 0, 1));
    CHECK(parked.file_peak() == ab_file);
    CHECK(parked.disk_bytes() >= ab);
    // a read back: its bytes go back to the disk (a hole before b), b's stay.
    parked.restore(a, {}, 0, 1);
    CHECK(a == a0);
    CHECK(parked.disk_bytes() >= bb);
    CHECK(parked.disk_bytes() <= bb + 2 * kBlock);
    // c fits in a's place: the file grows no longer.
    REQUIRE(parked.park(c, {}, 0, 1));
    CHECK(parked.file_peak() == ab_file);
    CHECK(parked.disk_bytes() <= bb + cb + 4 * kBlock);
    // a again does not fit before b any more: after it.
    REQUIRE(parked.park(a, {}, 0, 1));
    CHECK(parked.file_peak() == ab_file + up(a0.size() * 4));
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

TEST_CASE("Parked arrays go around the page cache where the file system allows it",
          "[pipeline][park]") {
    // Arrays of sizes that are not whole blocks, in a disk directory (O_DIRECT where its file
    // system takes it) and in memory (/dev/shm, tmpfs: through the cache).
    std::vector<fs::path> dirs{terrain::test::scratch_dir("parked_arrays_direct")};
    if (fs::is_directory("/dev/shm")) dirs.push_back("/dev/shm");
    for (const auto& dir : dirs) {
        // Whether the directory's file system takes O_DIRECT, asked of a file of its own.
        const auto probe = (dir / "terrain-direct-probe").string();
        const int fd = ::open(probe.c_str(), O_CREAT | O_RDWR | O_DIRECT, 0600);
        const bool takes_direct = fd >= 0;
        if (fd >= 0) ::close(fd);
        ::unlink(probe.c_str());
        INFO(dir.string() << (takes_direct ? " takes O_DIRECT" : " refuses O_DIRECT"));
        std::vector<std::uint16_t> a(33333);
        std::vector<double> b(70001);
        std::iota(a.begin(), a.end(), std::uint16_t{3});
        std::iota(b.begin(), b.end(), -0.5);
        std::vector<char> c(4097, 'x');
        c.back() = 'y';
        // Pages aligned as whole blocks in memory: moved from where they are.
        struct alignas(4096) Page {
            std::uint64_t words[512];
            bool operator==(const Page&) const = default;
        };
        std::vector<Page> pages(5);
        for (std::size_t i = 0; i < pages.size(); ++i)
            std::iota(pages[i].words, pages[i].words + 512, i);
        const auto a0 = a;
        const auto b0 = b;
        const auto c0 = c;
        const auto pages0 = pages;
        ParkedArrays parked(dir.string(), 0);
        parked.decide(1);
        REQUIRE(parked.on());
        CHECK(parked.direct() == takes_direct);
        REQUIRE(parked.park(pages, {}, 0, 1));
        REQUIRE(parked.park(a, {}, 0, 1));
        REQUIRE(parked.park(c, {}, 0, 1));
        REQUIRE(parked.park(b, {}, 0, 1));
        parked.restore(c, {}, 0, 1);
        parked.restore(b, {}, 0, 1);
        std::vector<char> d(100, 'd');  // into c's place, between a and b
        const auto d0 = d;
        REQUIRE(parked.park(d, {}, 0, 1));
        parked.restore(a, {}, 0, 1);
        parked.restore(d, {}, 0, 1);
        parked.restore(pages, {}, 0, 1);
        CHECK(pages == pages0);
        CHECK(a == a0);
        CHECK(b == b0);
        CHECK(c == c0);
        CHECK(d == d0);
        CHECK(parked.direct() == takes_direct);  // (no transfer fell back to the cache)
        CHECK(parked.disk_bytes() == 0);
    }
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
