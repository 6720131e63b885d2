#pragma once
// The terrain program's large blocks: freed ones kept, their pages resident, for the next
// large allocation, up to the peak the program has reached (docs/performance.md, "Large
// blocks reused"). tools/big_blocks.cpp routes the program's operator new and delete here;
// this header holds the bookkeeping so that tests can drive it.
//
// A whole-grid run allocates and frees arrays of gigabytes stage after stage: several times
// its peak in fresh pages over the run. The kernel zeroes every fresh page and, when memory
// is fragmented, first gathers free 2 MiB pages for it. Here a block of 4 MiB or more is a
// mapping of its own, 2 MiB aligned; freed, it is kept, and the next large allocation takes
// it: the smallest kept block at least as large (its tail kept as a block of its own), or
// else the largest one with fresh pages added behind it (its pages moved by mremap, not
// copied). Fresh pages are mapped only for what no kept block covers.
//
// The resident set does not grow for it. The process's resident memory, less the kept blocks
// (counted as resident), is what the program holds; its highest value so far is the peak.
// Kept blocks plus what the program holds stay under that peak, checked against the resident
// set (/proc/self/statm) at every large allocation and release, with the fresh pages a new
// block will take counted ahead, and whenever the caller's other blocks (note_grown: their
// allocations, not their frees, which the allocator may keep) have grown by more than the
// room left. To make room, kept blocks shrink from
// their tails, the largest first. give_back() returns every kept block.
//
// The bookkeeping allocates nothing (fixed tables of Slots blocks in use and Slots kept);
// allocate() returns nullptr when its table is full or the system refuses, and the caller
// falls back to malloc.

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>

namespace terrain::cli {

template <std::size_t Slots = 1024>
class LargeBlocks {
  public:
    static constexpr std::size_t kAlign = std::size_t{2} << 20;  // a huge page
    static constexpr std::size_t kLarge = std::size_t{4} << 20;  // the smallest block kept

    // The bytes the process holds resident (tests give their own). A 1/slack_share of the
    // peak stays free for what the program takes between two readings of the resident set
    // outside these blocks and the caller's counts (other threads' allocators, libraries);
    // 0: none.
    using ResidentFn = std::size_t (*)();
    explicit LargeBlocks(ResidentFn resident = &resident_bytes, std::size_t slack_share = 64)
        : resident_(resident), slack_share_(slack_share) {}
    LargeBlocks(const LargeBlocks&) = delete;
    LargeBlocks& operator=(const LargeBlocks&) = delete;
    ~LargeBlocks() { give_back(); }  // (blocks in use stay mapped: their owners hold them)

    // Whether fresh mappings ask for transparent huge pages (MADV_HUGEPAGE).
    void set_huge_pages(bool huge) { huge_pages_ = huge; }

    // A 2 MiB aligned block of at least n bytes, or nullptr.
    void* allocate(std::size_t n) {
        if (n > SIZE_MAX - 2 * kAlign) return nullptr;
        const std::size_t bytes = (n + kAlign - 1) / kAlign * kAlign;
        const std::lock_guard lock(mutex_);
        if (used_.full()) return nullptr;
        Block b = reuse(bytes);
        if (!b.start) return nullptr;
        // The caller touches at most its n bytes (whole huge pages when asked for): the fresh
        // pages beyond those a kept block brought.
        const std::size_t page = huge_pages_ ? kAlign : 4096;
        const std::size_t touched = std::min(bytes, (n + page - 1) / page * page);
        const std::size_t fresh = touched > b.touched ? touched - b.touched : 0;
        b.touched += fresh;
        used_.add(b);
        fit(fresh);
        return b.start;
    }

    // Whether p is a block in use from here (then it is kept, or unmapped when the table of
    // kept blocks is full).
    bool release(void* p) {
        const std::lock_guard lock(mutex_);
        const std::size_t i = used_.find(static_cast<char*>(p));
        if (i == Slots) return false;
        Block b = used_.take(i);
        if (kept_.full()) {
            unmap(b);
            fit(0);
        } else {
            const std::size_t held = settle(b);
            kept_.add(b);
            fit(0, held);  // (the peak counts it as held: it was, up to now)
        }
        return true;
    }

    // The caller's other blocks: `bytes` more allocated. Lock-free unless they have grown
    // past the room left under the peak since the resident set was last read.
    void note_grown(std::size_t bytes) {
        const std::size_t grown = grown_.fetch_add(bytes, std::memory_order_relaxed) + bytes;
        if (kept_total_.load(std::memory_order_relaxed) == 0 ||
            grown <= room_.load(std::memory_order_relaxed))
            return;
        const std::lock_guard lock(mutex_);
        fit(0);
    }

    // Every kept block unmapped; the peak starts again from what the process holds.
    void give_back() {
        const std::lock_guard lock(mutex_);
        while (kept_.count > 0) unmap(kept_.take(kept_.count - 1));
        peak_ = 0;
        fit(0);
    }

    struct Counts {
        std::size_t used_blocks, used_bytes, kept_blocks, kept_bytes, kept_touched, peak_bytes;
    };
    Counts counts() {
        const std::lock_guard lock(mutex_);
        return {used_.count, used_.bytes, kept_.count, kept_.bytes, kept_.touched, peak_};
    }

  private:
    struct Block {
        char* start = nullptr;
        std::size_t bytes = 0;    // a multiple of kAlign
        std::size_t touched = 0;  // the bytes at its front that may be resident
    };

    struct Table {
        std::array<Block, Slots> blocks{};
        std::size_t count = 0;
        std::size_t bytes = 0, touched = 0;

        bool full() const { return count == Slots; }
        void add(Block b) {
            blocks[count++] = b;
            bytes += b.bytes;
            touched += b.touched;
        }
        Block take(std::size_t i) {
            const Block b = blocks[i];
            blocks[i] = blocks[--count];
            bytes -= b.bytes;
            touched -= b.touched;
            return b;
        }
        // Block i cut to its first `keep` bytes; returns the cut tail.
        Block cut(std::size_t i, std::size_t keep) {
            Block& b = blocks[i];
            const Block tail{b.start + keep, b.bytes - keep,
                             b.touched > keep ? b.touched - keep : 0};
            b.bytes = keep;
            b.touched -= tail.touched;
            bytes -= tail.bytes;
            touched -= tail.touched;
            return tail;
        }
        std::size_t find(const char* p) const {
            for (std::size_t i = 0; i < count; ++i)
                if (blocks[i].start == p) return i;
            return Slots;
        }
    };

    // Its `touched`: the bytes at its front that a kept block's pages cover.
    Block reuse(std::size_t bytes) {
        std::size_t fit = Slots;
        for (std::size_t i = 0; i < kept_.count; ++i)
            if (kept_.blocks[i].bytes >= bytes &&
                (fit == Slots || kept_.blocks[i].bytes < kept_.blocks[fit].bytes))
                fit = i;
        if (fit != Slots) {
            Block b = kept_.take(fit);
            if (b.bytes > bytes) {  // its tail stays kept (in the slot just freed)
                kept_.add(
                    {b.start + bytes, b.bytes - bytes, b.touched > bytes ? b.touched - bytes : 0});
                b.bytes = bytes;
                b.touched = std::min(b.touched, bytes);
            }
            return b;
        }
        Block made = map(bytes);
        if (!made.start || kept_.count == 0) return made;
        const Block old = kept_.take(largest());  // smaller than `bytes`: no kept block fits
        if (::mremap(old.start, old.bytes, old.bytes, MREMAP_MAYMOVE | MREMAP_FIXED, made.start) ==
            MAP_FAILED)
            unmap(old);
        else
            made.touched = old.touched;
        return made;
    }

    std::size_t largest() const {
        std::size_t best = 0;
        for (std::size_t i = 1; i < kept_.count; ++i)
            if (kept_.blocks[i].bytes > kept_.blocks[best].bytes) best = i;
        return best;
    }

    // The peak raised to what the program holds (the resident set less the kept blocks'
    // touched pages); kept blocks shrunk from their tails (the most touched first) until they
    // fit under it beside what the program holds and the `fresh` pages a new block is about
    // to take. (The peak remembers only what was resident: pages asked for and never touched
    // do not raise it.) `released`: the touched bytes of a kept block that the program held
    // until now, counted in the peak.
    void fit(std::size_t fresh, std::size_t released = 0) {
        const std::size_t grown = grown_.load(std::memory_order_relaxed);
        const std::size_t resident = resident_();
        const std::size_t now = resident > kept_.touched ? resident - kept_.touched : 0;
        peak_ = std::max(peak_, now + released);
        const std::size_t slack = slack_share_ > 0 ? peak_ / slack_share_ : 0;
        const std::size_t held = now + fresh, bound = std::max(peak_ - slack, held);
        while (kept_.count > 0 && held + kept_.touched > bound) {
            const std::size_t over = held + kept_.touched - bound;
            std::size_t i = 0;  // the kept block with the most touched bytes
            for (std::size_t k = 1; k < kept_.count; ++k)
                if (kept_.blocks[k].touched > kept_.blocks[i].touched) i = k;
            const Block& b = kept_.blocks[i];
            const std::size_t cut = (over + kAlign - 1) / kAlign * kAlign;
            // Its tail from the last touched page on (the untouched rest goes with it).
            const std::size_t keep =
                b.touched > cut ? (b.touched - cut) / kAlign * kAlign : std::size_t{0};
            unmap(keep == 0 ? kept_.take(i) : kept_.cut(i, keep));
        }
        room_.store(bound - held - kept_.touched, std::memory_order_relaxed);
        grown_.fetch_sub(grown, std::memory_order_relaxed);  // (what grew meanwhile stays counted)
        kept_total_.store(kept_.touched, std::memory_order_relaxed);
    }

    // /proc/self/statm's resident pages, read without allocating.
    static std::size_t resident_bytes() {
        const int fd = ::open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
        if (fd < 0) return 0;
        char text[128];
        const ssize_t n = ::read(fd, text, sizeof text - 1);
        ::close(fd);
        if (n <= 0) return 0;
        text[n] = 0;
        const char* c = text;
        while (*c && *c != ' ') ++c;  // the first number: the whole mapped size
        std::size_t pages = 0;
        for (++c; *c >= '0' && *c <= '9'; ++c) pages = pages * 10 + std::size_t(*c - '0');
        return pages * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
    }

    Block map(std::size_t bytes) const {
        void* p = ::mmap(nullptr, bytes + kAlign, PROT_READ | PROT_WRITE,
                         MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED) return {};
        char* raw = static_cast<char*>(p);
        char* start = reinterpret_cast<char*>((reinterpret_cast<std::uintptr_t>(raw) + kAlign - 1) /
                                              kAlign * kAlign);
        const auto head = static_cast<std::size_t>(start - raw);
        if (head > 0) ::munmap(raw, head);
        if (kAlign - head > 0) ::munmap(start + bytes, kAlign - head);
        if (huge_pages_) ::madvise(start, bytes, MADV_HUGEPAGE);
        return {start, bytes};
    }

    static void unmap(Block b) { ::munmap(b.start, b.bytes); }

    // A block about to be kept, its `touched` made true to what is resident (mincore): its
    // owner may have left the end of its front untouched (then the front is the part up to
    // the first page not resident), or given pages back to the system inside it (the library
    // gives an array's pages back behind a pass that reads it for the last time: its next
    // owner would find fresh pages where they were counted resident), and then the whole
    // block goes back and none of it counts. Returns the resident bytes it had.
    static std::size_t settle(Block& b) {
        static const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
        unsigned char in[4096];
        std::size_t resident = 0, front = 0;
        bool gap = false, holed = false;
        for (std::size_t at = 0; at < b.touched; at += sizeof in * page) {
            const std::size_t len = std::min(b.touched - at, sizeof in * page);
            if (::mincore(b.start + at, len, in) != 0) return b.touched;  // (as it was)
            for (std::size_t k = 0; k < (len + page - 1) / page; ++k) {
                if (in[k] & 1) {
                    holed = gap;
                    resident += page;
                    if (!gap) front = at + (k + 1) * page;
                } else {
                    gap = true;
                }
            }
        }
        if (holed) {
            ::madvise(b.start, b.touched, MADV_DONTNEED);
            b.touched = 0;
        } else {
            b.touched = std::min(front, b.touched);
        }
        return resident;
    }

    ResidentFn resident_;
    std::size_t slack_share_;
    std::mutex mutex_;
    Table used_, kept_;
    std::size_t peak_ = 0;  // the most the program has held resident, kept blocks aside
    bool huge_pages_ = false;
    // For note_grown's test without the lock: the caller's other blocks' growth since the
    // resident set was last read, the room then left under the peak, the kept blocks' bytes.
    std::atomic<std::size_t> grown_{0}, room_{0};
    std::atomic<std::size_t> kept_total_{0};
};

}  // namespace terrain::cli
