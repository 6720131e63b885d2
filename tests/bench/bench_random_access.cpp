// Benchmark: what one random read of memory costs on this machine as the memory read grows,
// the cost behind the stages that read at random (the contour tree's sweeps, the
// simplification, the flooding of the absorbed vertices): a global grid of 265 M pixels holds
// 4 times the bytes of one of 66 M, and each of its random reads costs more.
//   build/tests/bench/bench_random_access [GiB ...]   (default 0.25 1 4 12)
// For each size, a block of 64-bit words (asking for transparent huge pages, as the program
// does) is read at random places: independent reads (several in flight, as in a prefetched
// pass) and a chain of reads each of whose address comes from the one before (one in flight:
// the latency). Prints nanoseconds a read.
// Then what a dependent read near the one before it costs, the second of a pair whose first
// is a chained random read and whose second lands within +-4 KiB, 64 KiB or 1 MiB of it: what
// a record read after another one costs when the two sit that near in memory (a numbering
// that keeps a cancellation's records near one another would save what these columns save on
// the chained column).

#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench_main.hpp"
#include "terrain/core/memory_budget.hpp"

namespace {

// The distances of the near reads, in bytes either way.
constexpr std::size_t kNear[] = {std::size_t{4} << 10, std::size_t{64} << 10, std::size_t{1} << 20};
constexpr std::size_t kNears = sizeof(kNear) / sizeof(kNear[0]);

struct Costs {
    double independent_ns = 0, chained_ns = 0;
    double near_ns[kNears] = {};
};

Costs measure(std::size_t bytes) {
    const std::size_t n = bytes / sizeof(std::uint64_t);
    void* block =
        ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (block == MAP_FAILED) {
        std::fprintf(stderr, "bench_random_access: cannot map %zu bytes\n", bytes);
        std::exit(1);
    }
    ::madvise(block, bytes, MADV_HUGEPAGE);
    auto* words = static_cast<std::uint64_t*>(block);
    for (std::size_t i = 0; i < n; ++i) words[i] = i * 0x9E3779B97F4A7C15ull;
    constexpr std::size_t kReads = 20'000'000;
    using Clock = std::chrono::steady_clock;
    const auto ns_per_read = [&](Clock::time_point from) {
        return std::chrono::duration<double, std::nano>(Clock::now() - from).count() / kReads;
    };
    Costs costs;
    // Independent: the addresses come from a generator, not from the words read.
    std::uint64_t x = 0x2545F4914F6CDD1Dull, sum = 0;
    auto start = Clock::now();
    for (std::size_t i = 0; i < kReads; ++i) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        sum += words[x % n];
    }
    costs.independent_ns = ns_per_read(start);
    // Chained: each address mixes the word just read with the step's number (no short cycle).
    const auto random_after = [&](std::uint64_t at, std::size_t i) {
        return (words[at] ^ (i + 1) * 0xBF58476D1CE4E5B9ull) % n;
    };
    std::uint64_t at = 1;
    start = Clock::now();
    for (std::size_t i = 0; i < kReads; ++i) at = random_after(at, i);
    costs.chained_ns = ns_per_read(start);
    // Pairs: a chained random read, then one within +-d bytes of it whose offset comes from
    // the word just read; the near read's cost is the pair's less a random read's.
    for (std::size_t k = 0; k < kNears; ++k) {
        const std::size_t span = std::min(n, 2 * (kNear[k] / sizeof(std::uint64_t)) + 1);
        const std::size_t half = span / 2;
        start = Clock::now();
        for (std::size_t i = 0; i < kReads / 2; ++i) {
            at = random_after(at, i);
            const std::size_t offset = (words[at] ^ (i + 1) * 0x94D049BB133111EBull) % span;
            at = at + offset < half ? 0 : std::min(n - 1, at + offset - half);
        }
        costs.near_ns[k] = 2 * ns_per_read(start) - costs.chained_ns;
    }
    ::munmap(block, bytes);
    if ((sum ^ at) == 42) std::printf(" ");  // (keeps the reads)
    return costs;
}

}  // namespace

static int run_bench(int argc, char** argv) {
    std::vector<double> sizes;
    for (int i = 1; i < argc; ++i) sizes.push_back(std::atof(argv[i]));
    if (sizes.empty()) sizes = {0.25, 1, 4, 12};
    std::printf("bench_random_access: ns a random 8-byte read, by the bytes read at random\n");
    std::printf("%8s %12s %10s %11s %11s %11s\n", "GiB", "independent", "chained", "near 4K",
                "near 64K", "near 1M");
    for (const double gib : sizes) {
        if (!(gib > 0)) {
            std::fprintf(stderr, "bench_random_access: sizes are GiB > 0\n");
            return 1;
        }
        const auto bytes = static_cast<std::size_t>(gib * double(std::size_t{1} << 30));
        // (Not a size that does not fit: the system would kill the process.)
        const auto available = terrain::available_memory();
        if (available && bytes > *available / 10 * 9) {
            std::printf("%8.2f      skipped (%.1f GiB available)\n", gib,
                        double(*available) / double(std::size_t{1} << 30));
            continue;
        }
        const Costs c = measure(bytes);
        std::printf("%8.2f %12.1f %10.1f %11.1f %11.1f %11.1f\n", gib, c.independent_ns,
                    c.chained_ns, c.near_ns[0], c.near_ns[1], c.near_ns[2]);
    }
    return 0;
}

int main(int argc, char** argv) {
    return terrain::bench::bench_main(argc, argv,
                                      "bench_random_access [GiB ...]: nanoseconds a random read of "
                                      "memory blocks of these sizes (default 0.25 1 4 12).",
                                      run_bench);
}
