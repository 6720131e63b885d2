#pragma once
// Private: large arrays parked in a temporary file while the stages that do not read them run
// (docs/performance.md, "Arrays parked on disk"). The Reeb graph and the simplification hold
// the run's peak of memory; the DEM's values, the field and the mesh's pixel maps wait beside
// them unread. Parked, they leave the resident set: their bytes go to a file the kernel writes
// back and may evict, and they are read back, the same bytes, before the growing.
//
// The file is unlinked as soon as it is made (O_TMPFILE, or a named file removed at once), so
// nothing is left behind whatever ends the process. It holds what is parked now, not all that
// was ever parked: an array read back gives its bytes back to the disk (a hole punched, the
// file cut after the last array still parked), and the next array parked goes in the first
// gap it fits between those still there. A directory that refuses the file, or a
// write that fails (a full disk), parks nothing more: the arrays stay in memory and the run
// goes on, the same. A read that fails throws terrain::Error: the data would be lost.
//
// The file is read and written around the page cache (O_DIRECT, each array at an offset of
// whole blocks; an array not aligned in memory, and the last partial block of each, through an
// aligned buffer of its own) where its file system allows it: pages of
// the cache are fresh memory, whose first touch costs more on a virtual machine than the disk
// itself (docs/performance.md, "Arrays parked on disk"), and the kernel's writing them back
// later takes the cores the run needs. Elsewhere (tmpfs) the file goes through the cache.
// Not installed.

#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "terrain/core/progress.hpp"
#include "terrain/internal/core/pass_progress.hpp"

namespace terrain::detail {

class ParkedArrays {
  public:
    // `dir`: where the file goes (empty: the system's temporary directory, $TMPDIR).
    // Arrays below `min_bytes` in all are not worth the file: parking them does nothing.
    ParkedArrays(std::string dir, std::size_t min_bytes);
    ~ParkedArrays();
    // Whether the file bypasses the page cache (O_DIRECT).
    bool direct() const { return direct_; }
    ParkedArrays(const ParkedArrays&) = delete;
    ParkedArrays& operator=(const ParkedArrays&) = delete;

    // Decides, from the bytes the arrays to be parked hold in all, whether to park them: when
    // they reach min_bytes and the file can be made.
    void decide(std::size_t bytes);
    bool decided() const { return decided_; }
    // Whether parking is on.
    bool on() const { return fd_ >= 0 && !full_; }

    // Writes v's elements to the file and frees v; returns false (v kept) when parking is
    // off or the write fails. Progress from `begin` to `end` of `progress`.
    template <class T>
    bool park(std::vector<T>& v, const ProgressFn& progress, double begin, double end) {
        static_assert(std::is_trivially_copyable_v<T>);
        if (!write(&v, v.data(), v.size(), sizeof(T), progress, begin, end)) return false;
        std::vector<T>().swap(v);
        return true;
    }
    // Reads back what park(v) wrote into v (nothing when v was not parked).
    template <class T>
    void restore(std::vector<T>& v, const ProgressFn& progress, double begin, double end) {
        const Entry* e = find(&v);
        if (!e) return;
        std::vector<T> back;
        detail::assign_in_slices(back, e->count, T{},
                                 detail::PassProgress(progress, begin, begin, "park"));
        read(*e, back.data(), progress, begin, end);
        v.swap(back);
        forget(&v);
    }
    // Bytes parked now.
    std::size_t parked_bytes() const;
    // The most bytes parked at once so far.
    std::size_t most_parked() const { return most_parked_; }
    // The file's largest length so far: the most disk the parked arrays took at once (gaps
    // between them included).
    std::size_t file_peak() const { return file_peak_; }
    // The disk space the file holds now (its allocated blocks; 0 without a file).
    std::size_t disk_bytes() const;

  private:
    struct Entry {
        const void* owner;
        std::uint64_t offset, count, size;
        // Where its bytes end, rounded up to whole blocks (each array starts on a block).
        std::uint64_t end() const;
    };
    // Moves up to `bytes` at `offset` of the file from or to `data` (when direct, whole blocks
    // from `data` if aligned, else through the aligned buffer); returns the bytes moved
    // (<= 0: failed).
    long transfer(bool writing, char* data, std::size_t bytes, std::uint64_t offset);
    bool write(const void* owner, const void* data, std::size_t count, std::size_t size,
               const ProgressFn& progress, double begin, double end);
    void read(const Entry& e, void* data, const ProgressFn& progress, double begin, double end);
    const Entry* find(const void* owner) const;
    void forget(const void* owner);
    // Where an array of `bytes` goes: the first gap between the arrays parked that holds it,
    // else after the last of them.
    std::uint64_t place(std::uint64_t bytes) const;
    // The end of the last array parked (0 for none); cut() cuts the file there.
    std::uint64_t parked_end() const;
    void cut();

    std::string dir_;
    std::size_t min_bytes_;
    int fd_ = -1;
    bool full_ = false;       // a write failed: nothing more is parked
    bool decided_ = false;    // decide() was called
    bool direct_ = false;     // O_DIRECT: moved in whole blocks (buffer_ when unaligned)
    char* buffer_ = nullptr;  // (aligned, 4 MiB, made on first use)
    std::uint64_t file_peak_ = 0;
    std::size_t most_parked_ = 0;
    std::vector<Entry> entries_;  // by offset
};

}  // namespace terrain::detail
