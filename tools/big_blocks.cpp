// The program's operator new and delete: blocks of 4 MiB or more go through LargeBlocks
// (tools/large_blocks.hpp: freed ones kept for the next large allocation, up to the peak the
// program has reached), the rest to malloc, their sizes counted there as they are made.
// docs/performance.md, "Large blocks reused".
//
// The replacements are the program's own (the library and the Python module keep the system
// allocator). A pointer not 2 MiB aligned is never one of these blocks, so the common delete
// costs one test; an aligned one is looked up. Sanitized builds leave this file out (their
// runtime checks every block), and TERRAIN_LARGE_BLOCKS=0 turns it off. The library's release of
// its free memory (terrain::release_free_memory: before the outputs are written, whose libraries
// allocate on their own, and once the large arrays are freed) gives the kept blocks back.

#include <malloc.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>

#include "large_blocks.hpp"
#include "terrain/core/huge_pages.hpp"
#include "terrain/core/memory_budget.hpp"

namespace {

using Blocks = terrain::cli::LargeBlocks<>;

// Made on first use and never destroyed: deletes may come after static destructors.
Blocks& blocks() {
    alignas(Blocks) static unsigned char storage[sizeof(Blocks)];
    static Blocks* made = new (storage) Blocks;
    return *made;
}

// TERRAIN_LARGE_BLOCKS=0: every block from malloc (to compare, or for a memory checker).
bool enabled = false;

// Before main: whether blocks are kept, the page size to ask for (huge pages as glibc asks for its
// own mappings when this run has them; a block allocated before this has normal pages), and the
// library's release of its free memory gives back the kept blocks too.
[[maybe_unused]] const bool registered = [] {
    const char* choice = std::getenv("TERRAIN_LARGE_BLOCKS");
    if (choice && std::strcmp(choice, "0") == 0) return false;
    enabled = true;
    blocks().set_huge_pages(terrain::huge_page_use() == "huge");
    terrain::set_free_memory_release([] { blocks().give_back(); });
    return true;
}();

// A block of n bytes aligned to `align` (a power of two): a large block (2 MiB aligned) when
// it may be one, else from malloc (aligned_alloc beyond malloc's own alignment), its size
// counted. (Over-aligned types, as the simplification's 32-byte records, come through here too:
// left to the system's allocator they were neither kept nor counted, and the kept blocks then
// overran the peak by as much as those records took beyond what was counted.)
void* allocate(std::size_t n, std::size_t align = __STDCPP_DEFAULT_NEW_ALIGNMENT__) {
    if (n >= Blocks::kLarge && enabled && align <= Blocks::kAlign)
        if (void* p = blocks().allocate(n)) return p;
    for (;;) {
        const std::size_t bytes = n == 0 ? 1 : n;
        void* p = align <= __STDCPP_DEFAULT_NEW_ALIGNMENT__
                      ? std::malloc(bytes)
                      : std::aligned_alloc(align, (bytes + align - 1) / align * align);
        if (p) {
            if (enabled) blocks().note_grown(malloc_usable_size(p));
            return p;
        }
        const std::new_handler handler = std::get_new_handler();
        if (!handler) throw std::bad_alloc();
        handler();
    }
}

void release(void* p) noexcept {
    if (!p) return;
    if (enabled && reinterpret_cast<std::uintptr_t>(p) % Blocks::kAlign == 0 && blocks().release(p))
        return;
    std::free(p);
}

}  // namespace

void* operator new(std::size_t n) {
    return allocate(n);
}
void* operator new[](std::size_t n) {
    return allocate(n);
}
void operator delete(void* p) noexcept {
    release(p);
}
void operator delete[](void* p) noexcept {
    release(p);
}
void operator delete(void* p, std::size_t) noexcept {
    release(p);
}
void operator delete[](void* p, std::size_t) noexcept {
    release(p);
}
void* operator new(std::size_t n, std::align_val_t a) {
    return allocate(n, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t n, std::align_val_t a) {
    return allocate(n, static_cast<std::size_t>(a));
}
void operator delete(void* p, std::align_val_t) noexcept {
    release(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
    release(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
    release(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
    release(p);
}

// (tests/tools/big_blocks_probe.cpp) What the blocks hold now.
terrain::cli::LargeBlocks<>::Counts terrain_large_block_counts() {
    return blocks().counts();
}
