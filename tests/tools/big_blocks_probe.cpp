// A program with the terrain program's operator new and delete (tools/big_blocks.cpp): it
// allocates large blocks of plain and over-aligned types and prints what the blocks hold
// after each step, for tests/tools/large_blocks.cpp.

#include <cstdint>
#include <cstdio>
#include <memory>
#include <vector>

#include "tools/large_blocks.hpp"

terrain::cli::LargeBlocks<>::Counts terrain_large_block_counts();

namespace {

struct alignas(32) Record {
    std::uint64_t a[4];
};
struct alignas(4096) Page {
    unsigned char bytes[4096];
};

void print(const char* step) {
    const auto c = terrain_large_block_counts();
    std::printf("%s used %zu %zu kept %zu %zu\n", step, c.used_blocks, c.used_bytes, c.kept_blocks,
                c.kept_bytes);
}

}  // namespace

int main() {
    constexpr std::size_t MiB = std::size_t{1} << 20;
    print("start");
    {
        std::vector<std::uint32_t> plain(8 * MiB / sizeof(std::uint32_t), 1);
        print("plain");
        std::vector<Record> records(16 * MiB / sizeof(Record));
        print("records");
        auto pages = std::make_unique<Page[]>(8 * MiB / sizeof(Page));
        print("pages");
        auto small = std::make_unique<Record[]>(16);
        print("small");
        std::printf("aligned %d %d %d\n",
                    reinterpret_cast<std::uintptr_t>(records.data()) % alignof(Record) == 0,
                    reinterpret_cast<std::uintptr_t>(pages.get()) % alignof(Page) == 0,
                    reinterpret_cast<std::uintptr_t>(small.get()) % alignof(Record) == 0);
    }
    print("freed");
    return 0;
}
