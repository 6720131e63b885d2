// Arrays parked in an unlinked temporary file (parked_arrays.hpp).

#include "parked_arrays.hpp"

#include <fcntl.h>
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
    const auto* bytes = static_cast<const char*>(data);
    for (std::size_t done = 0; done < total;) {
        const std::size_t n = std::min(kChunk, total - done);
        const ssize_t w = ::pwrite(fd_, bytes + done, n, static_cast<off_t>(end_ + done));
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {      // a full disk, say: nothing more is parked, this array stays
            full_ = true;  // (the file stays open: the arrays parked before are read back)
            return false;
        }
        done += static_cast<std::size_t>(w);
        report_progress(progress, begin + (end - begin) * double(done) / double(total), "park");
    }
    entries_.push_back({owner, end_, count, size});
    end_ += total;
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
    std::erase_if(entries_, [&](const Entry& e) { return e.owner == owner; });
}

std::size_t ParkedArrays::parked_bytes() const {
    std::size_t bytes = 0;
    for (const Entry& e : entries_) bytes += e.count * e.size;
    return bytes;
}

}  // namespace terrain::pipeline::internal
