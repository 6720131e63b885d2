#include <sys/mman.h>
#include <unistd.h>
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "support/test_support.hpp"
#include "tools/large_blocks.hpp"

using terrain::cli::LargeBlocks;

namespace {

constexpr std::size_t MiB = std::size_t{1} << 20;

bool aligned(const void* p) {
    return reinterpret_cast<std::uintptr_t>(p) % (2 * MiB) == 0;
}

// Writes a pattern over n bytes, seeded by `seed`; `holds` checks it.
void fill(void* p, std::size_t n, unsigned seed) {
    auto* b = static_cast<unsigned char*>(p);
    for (std::size_t i = 0; i < n; i += 4096) b[i] = static_cast<unsigned char>(seed + i / 4096);
    b[n - 1] = static_cast<unsigned char>(seed * 7 + 1);
}
bool holds(const void* p, std::size_t n, unsigned seed) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; i += 4096)
        if (b[i] != static_cast<unsigned char>(seed + i / 4096)) return false;
    return b[n - 1] == static_cast<unsigned char>(seed * 7 + 1);
}

// The resident set the deterministic tests model by hand: the bytes of the blocks they have
// touched, in use or kept.
std::size_t modelled = 0;
std::size_t modelled_resident() {
    return modelled;
}

// A fresh block of n bytes from `blocks`, every page touched and added to the model.
template <class Blocks>
void* touched(Blocks& blocks, std::size_t n, unsigned seed) {
    void* p = blocks.allocate(n);
    REQUIRE(p != nullptr);
    fill(p, n, seed);
    modelled += n;
    return p;
}

// The process's resident set, for the test that runs on the real one.
std::size_t resident() {
    std::ifstream statm("/proc/self/statm");
    std::size_t size = 0, pages = 0;
    statm >> size >> pages;
    return pages * static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
}

}  // namespace

TEST_CASE(
    "large blocks are 2 MiB aligned, writable, and a freed one is taken again with its pages") {
    modelled = 0;
    LargeBlocks<16> blocks(&modelled_resident, 0);
    void* a = blocks.allocate(6 * MiB - 100);  // rounded up to 6 MiB
    REQUIRE(a != nullptr);
    CHECK(aligned(a));
    fill(a, 6 * MiB - 100, 3);
    modelled = 6 * MiB;
    CHECK(blocks.counts().used_bytes == 6 * MiB);
    REQUIRE(blocks.release(a));
    CHECK(blocks.counts().kept_bytes == 6 * MiB);

    // The same size again: the same block, its contents still there (no fresh pages).
    void* b = blocks.allocate(6 * MiB);
    CHECK(b == a);
    CHECK(holds(b, 6 * MiB - 100, 3));
    CHECK(blocks.counts().kept_blocks == 0);
    REQUIRE(blocks.release(b));

    // A smaller one: the front of the kept block; its tail stays kept, 2 MiB aligned.
    void* c = blocks.allocate(4 * MiB);
    CHECK(c == a);
    const auto counts = blocks.counts();
    CHECK(counts.kept_blocks == 1);
    CHECK(counts.kept_bytes == 2 * MiB);
    void* tail = blocks.allocate(2 * MiB);
    CHECK(tail == static_cast<char*>(a) + 4 * MiB);
    CHECK(aligned(tail));
    CHECK(blocks.release(c));
    CHECK(blocks.release(tail));
}

TEST_CASE("a block larger than any kept one moves the largest kept block's pages to its front") {
    modelled = 0;
    LargeBlocks<16> blocks(&modelled_resident, 0);
    void* small = touched(blocks, 4 * MiB, 5);
    void* large = touched(blocks, 8 * MiB, 9);
    REQUIRE(blocks.release(small));
    REQUIRE(blocks.release(large));
    CHECK(blocks.counts().peak_bytes == 12 * MiB);

    void* grown = blocks.allocate(12 * MiB);
    REQUIRE(grown != nullptr);
    CHECK(aligned(grown));
    CHECK(holds(grown, 8 * MiB, 9));  // the 8 MiB block's pages, moved and not copied
    std::memset(static_cast<char*>(grown) + 8 * MiB, 1, 4 * MiB);  // the fresh rest is mapped
    // Held plus kept would be 16 MiB, past the peak of 12: the small kept block went back.
    const auto counts = blocks.counts();
    CHECK(counts.used_bytes == 12 * MiB);
    CHECK(counts.kept_bytes == 0);
    CHECK(blocks.release(grown));
}

TEST_CASE("the resident set never passes the peak of what the program holds, kept blocks aside") {
    // On the process's real resident set: blocks from here and other blocks from malloc,
    // taken and freed at random, every page touched.
    LargeBlocks<64> blocks;
    std::mt19937 random(17);
    std::vector<std::pair<void*, std::size_t>> live, other;
    std::size_t peak = 0, most_kept = 0;
    for (int step = 0; step < 600; ++step) {
        const auto choice = random() % 10;
        if (choice < 3) {
            // Other blocks from malloc, their allocations counted through note_grown.
            if (other.empty() || random() % 2 == 0) {
                const std::size_t n = 1 * MiB + random() % (12 * MiB);
                void* p = std::malloc(n);
                REQUIRE(p != nullptr);
                std::memset(p, 1, n);
                blocks.note_grown(n);
                other.push_back({p, n});
            } else {
                const std::size_t i = random() % other.size();
                std::free(other[i].first);
                other[i] = other.back();
                other.pop_back();
            }
        } else if (live.empty() || (live.size() < 30 && choice < 7)) {
            const std::size_t n = 4 * MiB + random() % (24 * MiB);
            void* p = blocks.allocate(n);
            REQUIRE(p != nullptr);
            REQUIRE(aligned(p));
            fill(p, n, static_cast<unsigned>(step));
            live.push_back({p, n});
        } else {
            const std::size_t i = random() % live.size();
            REQUIRE(blocks.release(live[i].first));
            live[i] = live.back();
            live.pop_back();
        }
        const auto counts = blocks.counts();
        const std::size_t now = resident();
        REQUIRE(now >= counts.kept_touched);  // (kept blocks' touched pages are resident)
        peak = std::max(peak, now - counts.kept_touched);
        INFO("step " << step << " choice " << choice << ": resident " << now << ", kept "
                     << counts.kept_bytes << " class peak " << counts.peak_bytes << " test peak "
                     << peak << " live " << live.size() << " other " << other.size());
        REQUIRE(now <= peak + MiB);  // (1 MiB: the test's own small allocations)
        most_kept = std::max(most_kept, counts.kept_bytes);
    }
    CHECK(most_kept > 64 * MiB);  // (blocks were kept: keeping none would meet the bound)
    // No two blocks in use overlap: each still holds what was written last into it.
    std::sort(live.begin(), live.end());
    for (std::size_t i = 1; i < live.size(); ++i)
        CHECK(static_cast<char*>(live[i - 1].first) + live[i - 1].second <=
              static_cast<char*>(live[i].first));
    for (auto& [p, n] : live) CHECK(blocks.release(p));
    for (auto& [p, n] : other) std::free(p);
    blocks.give_back();
    const auto counts = blocks.counts();
    CHECK(counts.kept_bytes == 0);
    CHECK(counts.kept_blocks == 0);
}

TEST_CASE("other blocks growing shrink the largest kept block from its tail") {
    modelled = 0;
    LargeBlocks<16> blocks(&modelled_resident, 0);
    void* a = touched(blocks, 8 * MiB, 7);
    void* b = touched(blocks, 16 * MiB, 11);
    REQUIRE(blocks.release(a));
    REQUIRE(blocks.release(b));
    auto counts = blocks.counts();
    REQUIRE(counts.kept_bytes == 24 * MiB);
    REQUIRE(counts.peak_bytes == 24 * MiB);
    // 3 MiB more elsewhere: 3 over the peak, and 4 MiB cut from the 16 MiB block.
    modelled += 3 * MiB;
    blocks.note_grown(3 * MiB);
    counts = blocks.counts();
    CHECK(counts.kept_blocks == 2);
    CHECK(counts.kept_bytes == 20 * MiB);
    modelled -= 4 * MiB;
    // Less than the room left (1 MiB) more: nothing cut.
    modelled += MiB / 2;
    blocks.note_grown(MiB / 2);
    CHECK(blocks.counts().kept_bytes == 20 * MiB);
    // What is left of the block is its front, with its pages: taken again for 12 MiB.
    void* c = blocks.allocate(12 * MiB);
    CHECK(c == b);
    const auto* bytes = static_cast<const unsigned char*>(c);
    bool same = true;
    for (std::size_t i = 0; i < 12 * MiB; i += 4096)
        same = same && bytes[i] == static_cast<unsigned char>(11 + i / 4096);
    CHECK(same);
    CHECK(blocks.release(c));
}

TEST_CASE("large blocks: a full table and an unknown pointer are left to the caller") {
    LargeBlocks<2> blocks;
    void* a = blocks.allocate(4 * MiB);
    void* b = blocks.allocate(4 * MiB);
    REQUIRE(a != nullptr);
    REQUIRE(b != nullptr);
    CHECK(blocks.allocate(4 * MiB) == nullptr);  // the caller falls back to malloc
    int local = 0;
    CHECK_FALSE(blocks.release(&local));
    CHECK(blocks.release(a));
    CHECK_FALSE(blocks.release(a));                      // not in use any more
    CHECK(blocks.allocate(std::size_t(-1)) == nullptr);  // a size that cannot be rounded up
    CHECK(blocks.release(b));
    blocks.give_back();
    CHECK(blocks.counts().kept_bytes == 0);
}

TEST_CASE("large blocks leave a share of the peak free") {
    modelled = 0;
    LargeBlocks<16> blocks(&modelled_resident, 4);  // a quarter of the peak left free
    void* a = touched(blocks, 8 * MiB, 1);
    void* b = touched(blocks, 8 * MiB, 2);
    REQUIRE(blocks.release(a));  // the peak: 16 MiB, 4 of it left free
    auto counts = blocks.counts();
    CHECK(counts.peak_bytes == 16 * MiB);
    CHECK(counts.kept_bytes == 4 * MiB);  // 8 held, 4 kept: 4 MiB cut from its tail
    modelled = 12 * MiB;
    REQUIRE(blocks.release(b));
    counts = blocks.counts();
    CHECK(counts.kept_bytes == 12 * MiB);
    CHECK(counts.kept_touched == 12 * MiB);
}

TEST_CASE("a kept block counts only the pages its owner left resident") {
    // Pages given back inside a block (the library's PagesBehind, madvise) would otherwise be
    // counted resident and found fresh by the block's next owner, past the peak.
    LargeBlocks<8> blocks(&resident, 0);
    const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    // Every page touched: kept whole.
    auto* p = static_cast<char*>(blocks.allocate(32 * MiB));
    REQUIRE(p != nullptr);
    fill(p, 32 * MiB, 1);
    REQUIRE(blocks.release(p));
    CHECK(blocks.counts().kept_touched == 32 * MiB);
    // Its front half given back: the whole block goes back, none of it counted.
    p = static_cast<char*>(blocks.allocate(32 * MiB));
    REQUIRE(p != nullptr);
    fill(p, 32 * MiB, 2);
    ::madvise(p, 16 * MiB, MADV_DONTNEED);
    REQUIRE(blocks.release(p));
    CHECK(blocks.counts().kept_touched == 0);
    CHECK(terrain::test::resident_bytes(p, 32 * MiB) == 0);
    // Only its first 8 MiB touched: those are counted, and stay.
    p = static_cast<char*>(blocks.allocate(32 * MiB));
    REQUIRE(p != nullptr);
    fill(p, 8 * MiB, 3);
    REQUIRE(blocks.release(p));
    CHECK(blocks.counts().kept_touched == 8 * MiB);
    CHECK(terrain::test::resident_bytes(p, 8 * MiB) == 8 * MiB);
    CHECK(holds(p, 8 * MiB, 3));
    // A page given back in the middle: none counted.
    p = static_cast<char*>(blocks.allocate(32 * MiB));
    REQUIRE(p != nullptr);
    fill(p, 32 * MiB, 4);
    ::madvise(p + 20 * MiB, page, MADV_DONTNEED);
    REQUIRE(blocks.release(p));
    CHECK(blocks.counts().kept_touched == 0);
    blocks.give_back();
}

#ifdef TERRAIN_BIG_BLOCKS_PROBE
TEST_CASE("The program's operator new takes large blocks of over-aligned types too",
          "[cli][memory]") {
    // tests/tools/big_blocks_probe.cpp: 8 MiB of plain words, 16 MiB of 32-byte aligned
    // records, 8 MiB of 4 KiB aligned pages, then a few small records; all freed.
    const auto r = terrain::test::run_program(TERRAIN_BIG_BLOCKS_PROBE, {});
    INFO(r.out << r.err);
    REQUIRE(r.status == 0);
    const auto line = [&](const std::string& step) {
        const auto at = r.out.find(step + " used ");
        REQUIRE(at != std::string::npos);
        std::size_t used_blocks, used_bytes, kept_blocks, kept_bytes;
        REQUIRE(std::sscanf(r.out.c_str() + at + step.size(), " used %zu %zu kept %zu %zu",
                            &used_blocks, &used_bytes, &kept_blocks, &kept_bytes) == 4);
        return std::array<std::size_t, 4>{used_blocks, used_bytes, kept_blocks, kept_bytes};
    };
    const auto start = line("start");
    CHECK(line("plain")[0] == start[0] + 1);
    CHECK(line("records")[0] == start[0] + 2);  // (32-byte alignment)
    CHECK(line("records")[1] == start[1] + 24 * MiB);
    CHECK(line("pages")[0] == start[0] + 3);  // (4 KiB alignment)
    CHECK(line("small")[0] == start[0] + 3);  // (small blocks from malloc)
    CHECK_THAT(r.out, Catch::Matchers::Contains("aligned 1 1 1"));
    const auto freed = line("freed");
    CHECK(freed[0] == start[0]);
    // Kept for reuse, as many as fit under the peak.
    CHECK(freed[2] > start[2]);
    CHECK(freed[2] <= start[2] + 3);
    CHECK(freed[3] > start[3] + 16 * MiB);
    CHECK(freed[3] <= start[3] + 32 * MiB);
}
#endif
