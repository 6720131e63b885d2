// Arrays parked in an unlinked temporary file (parked_arrays.hpp).

#include "terrain/internal/core/parked_arrays.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "terrain/core/error.hpp"

namespace terrain::detail {

namespace {

// Bytes moved by one system call: a report after each.
constexpr std::size_t kChunk = std::size_t{64} << 20;
// The block direct transfers are aligned to, in memory and in the file, and the buffer that
// moves the bytes of an array not so aligned (the large blocks of the program are).
constexpr std::size_t kBlock = 4096, kBuffer = std::size_t{4} << 20;

std::uint64_t round_up(std::uint64_t bytes) {
    return (bytes + kBlock - 1) / kBlock * kBlock;
}

}  // namespace

ParkedArrays::ParkedArrays(std::string dir, std::size_t min_bytes)
    : dir_(std::move(dir)), min_bytes_(min_bytes) {}

ParkedArrays::~ParkedArrays() {
    if (fd_ >= 0) ::close(fd_);
    std::free(buffer_);
}

std::uint64_t ParkedArrays::Entry::end() const {
    return offset + round_up(count * size);
}

void ParkedArrays::decide(std::size_t bytes) {
    decided_ = true;
    if (fd_ >= 0 || bytes == 0 || bytes < min_bytes_) return;
    std::error_code ec;
    std::string dir = dir_;
    if (dir.empty()) dir = std::filesystem::temp_directory_path(ec).string();
    if (ec || dir.empty()) return;
#ifdef O_TMPFILE
    fd_ = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
#endif
    if (fd_ < 0) {  // a file system without O_TMPFILE: a named file, removed at once
        std::string name = (std::filesystem::path(dir) / "terrain-parked-XXXXXX").string();
        fd_ = ::mkstemp(name.data());
        if (fd_ >= 0) ::unlink(name.c_str());
    }
    // Around the page cache where the file system allows it (not tmpfs).
    if (fd_ >= 0) {
        const int flags = ::fcntl(fd_, F_GETFL);
        direct_ = flags >= 0 && ::fcntl(fd_, F_SETFL, flags | O_DIRECT) == 0;
    }
}

long ParkedArrays::transfer(bool writing, char* data, std::size_t bytes, std::uint64_t offset) {
    for (;;) {
        if (direct_ && !buffer_) {
            buffer_ = static_cast<char*>(std::aligned_alloc(kBlock, kBuffer));
            if (!buffer_) direct_ = false;  // (then through the cache)
        }
        ssize_t n;
        const auto moved = [&](char* at, std::size_t count) {
            return writing ? ::pwrite(fd_, at, count, static_cast<off_t>(offset))
                           : ::pread(fd_, at, count, static_cast<off_t>(offset));
        };
        if (!direct_) {
            n = moved(data, bytes);
        } else if (reinterpret_cast<std::uintptr_t>(data) % kBlock == 0 && bytes >= kBlock) {
            n = moved(data, bytes / kBlock * kBlock);  // whole blocks, from where they are
        } else {
            // Through the buffer, in whole blocks: a last partial one padded (its bytes past
            // the array unread).
            const std::size_t count = std::min(bytes, kBuffer), whole = round_up(count);
            if (writing) {
                std::memcpy(buffer_, data, count);
                std::memset(buffer_ + count, 0, whole - count);
            }
            n = moved(buffer_, whole);
            if (n > 0) n = static_cast<ssize_t>(std::min(count, std::size_t(n)));
            if (!writing && n > 0) std::memcpy(data, buffer_, std::size_t(n));
        }
        if (n < 0 && errno == EINTR) continue;
        // A file system that took the flag but refuses the transfer: through the cache from
        // now on (the blocks already moved read back the same either way).
        if (n < 0 && errno == EINVAL && direct_) {
            const int flags = ::fcntl(fd_, F_GETFL);
            if (flags >= 0 && ::fcntl(fd_, F_SETFL, flags & ~O_DIRECT) == 0) {
                direct_ = false;
                continue;
            }
        }
        return static_cast<long>(n);
    }
}

bool ParkedArrays::write(const void* owner, const void* data, std::size_t count, std::size_t size,
                         const ProgressFn& progress, double begin, double end) {
    if (!on() || count == 0 || find(owner)) return false;
    const std::size_t total = count * size;
    const std::uint64_t at = place(round_up(total));
    auto* bytes = const_cast<char*>(static_cast<const char*>(data));  // (only read)
    for (std::size_t done = 0; done < total;) {
        const std::size_t n = std::min(kChunk, total - done);
        const long w = transfer(true, bytes + done, n, at + done);
        if (w <= 0) {      // a full disk, say: nothing more is parked, this array stays
            full_ = true;  // (the file stays open: the arrays parked before are read back)
            if (at >= parked_end()) cut();  // (what was written of it goes)
            return false;
        }
        done += static_cast<std::size_t>(w);
        report_progress(progress, begin + (end - begin) * double(done) / double(total), "park");
    }
    const Entry e{owner, at, count, size};
    entries_.insert(
        std::upper_bound(entries_.begin(), entries_.end(), e,
                         [](const Entry& a, const Entry& b) { return a.offset < b.offset; }),
        e);
    file_peak_ = std::max(file_peak_, at + round_up(total));
    most_parked_ = std::max(most_parked_, parked_bytes());
    return true;
}

void ParkedArrays::read(const Entry& e, void* data, const ProgressFn& progress, double begin,
                        double end) {
    const std::size_t total = e.count * e.size;
    auto* bytes = static_cast<char*>(data);
    for (std::size_t done = 0; done < total;) {
        const std::size_t n = std::min(kChunk, total - done);
        const long r = transfer(false, bytes + done, n, e.offset + done);
        if (r <= 0)
            throw Error("segment", std::string("cannot read back the arrays parked on disk: ") +
                                       (r < 0 ? std::strerror(errno) : "the file is short"));
        done += static_cast<std::size_t>(r);
        report_progress(progress, begin + (end - begin) * double(done) / double(total), "park");
    }
}

const ParkedArrays::Entry* ParkedArrays::find(const void* owner) const {
    for (const Entry& e : entries_)
        if (e.owner == owner) return &e;
    return nullptr;
}

void ParkedArrays::forget(const void* owner) {
    const Entry* e = find(owner);
    if (!e) return;
    const std::uint64_t offset = e->offset, bytes = e->end() - e->offset;
    std::erase_if(entries_, [&](const Entry& x) { return x.owner == owner; });
    // Its bytes go back to the disk (both best effort: a file system that cannot punch holes
    // keeps them until the file is cut or closed, and the next arrays reuse the gap).
    if (offset >= parked_end())
        cut();
    else
        (void)::fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE,
                          static_cast<off_t>(offset), static_cast<off_t>(bytes));
}

std::uint64_t ParkedArrays::parked_end() const {
    if (entries_.empty()) return 0;
    return entries_.back().end();
}

void ParkedArrays::cut() {
    (void)::ftruncate(fd_, static_cast<off_t>(parked_end()));
}

std::uint64_t ParkedArrays::place(std::uint64_t bytes) const {
    std::uint64_t at = 0;
    for (const Entry& e : entries_) {
        if (e.offset >= at + bytes) return at;
        at = e.end();
    }
    return at;
}

std::size_t ParkedArrays::disk_bytes() const {
    struct stat st {};
    if (fd_ < 0 || ::fstat(fd_, &st) != 0) return 0;
    return static_cast<std::size_t>(st.st_blocks) * 512;
}

std::size_t ParkedArrays::parked_bytes() const {
    std::size_t bytes = 0;
    for (const Entry& e : entries_) bytes += e.count * e.size;
    return bytes;
}

}  // namespace terrain::detail
