// Arrays parked in an unlinked temporary file (parked_arrays.hpp).

#include "parked_arrays.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "terrain/core/error.hpp"

namespace terrain::pipeline::internal {

namespace {

// Bytes moved by one system call: a report after each.
constexpr std::size_t kChunk = std::size_t{64} << 20;

}  // namespace

ParkedArrays::ParkedArrays(std::string dir, std::size_t min_bytes)
    : dir_(std::move(dir)), min_bytes_(min_bytes) {}

ParkedArrays::~ParkedArrays() {
    if (fd_ >= 0) ::close(fd_);
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
}

bool ParkedArrays::write(const void* owner, const void* data, std::size_t count, std::size_t size,
                         const ProgressFn& progress, double begin, double end) {
    if (!on() || count == 0 || find(owner)) return false;
    const std::size_t total = count * size;
    const std::uint64_t at = place(total);
    const auto* bytes = static_cast<const char*>(data);
    for (std::size_t done = 0; done < total;) {
        const std::size_t n = std::min(kChunk, total - done);
        const ssize_t w = ::pwrite(fd_, bytes + done, n, static_cast<off_t>(at + done));
        if (w < 0 && errno == EINTR) continue;
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
    file_peak_ = std::max(file_peak_, at + total);
    return true;
}

void ParkedArrays::read(const Entry& e, void* data, const ProgressFn& progress, double begin,
                        double end) {
    const std::size_t total = e.count * e.size;
    auto* bytes = static_cast<char*>(data);
    for (std::size_t done = 0; done < total;) {
        const std::size_t n = std::min(kChunk, total - done);
        const ssize_t r = ::pread(fd_, bytes + done, n, static_cast<off_t>(e.offset + done));
        if (r < 0 && errno == EINTR) continue;
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
    const std::uint64_t offset = e->offset, bytes = e->count * e->size;
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
    const Entry& last = entries_.back();
    return last.offset + last.count * last.size;
}

void ParkedArrays::cut() {
    (void)::ftruncate(fd_, static_cast<off_t>(parked_end()));
}

std::uint64_t ParkedArrays::place(std::uint64_t bytes) const {
    std::uint64_t at = 0;
    for (const Entry& e : entries_) {
        if (e.offset >= at + bytes) return at;
        at = e.offset + e.count * e.size;
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

}  // namespace terrain::pipeline::internal
