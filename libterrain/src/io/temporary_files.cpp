#include "terrain/io/temporary_files.hpp"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <system_error>
#include <vector>

namespace terrain::io {
namespace {

constexpr int kSlots = 64;
constexpr std::size_t kPathBytes = 4096;
// Fixed storage: the signal handler reads it without allocating or locking.
char slot_paths[kSlots][kPathBytes];
std::atomic<bool> slot_used[kSlots];
std::mutex registry_mutex;

bool process_alive(long pid) {
    if (pid <= 0) return true;  // not a process id: leave the file alone
    if (pid == ::getpid()) return true;
    return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
}

}  // namespace

void register_temporary(const std::string& path) {
    if (path.size() + 1 > kPathBytes) return;
    const std::lock_guard lock(registry_mutex);
    for (int i = 0; i < kSlots; ++i)
        if (!slot_used[i].load()) {
            std::memcpy(slot_paths[i], path.c_str(), path.size() + 1);
            slot_used[i].store(true);
            return;
        }
}

void unregister_temporary(const std::string& path) {
    const std::lock_guard lock(registry_mutex);
    for (int i = 0; i < kSlots; ++i)
        if (slot_used[i].load() && path == slot_paths[i]) {
            slot_used[i].store(false);
            return;
        }
}

void remove_registered_temporaries() noexcept {
    for (int i = 0; i < kSlots; ++i)
        if (slot_used[i].load()) ::unlink(slot_paths[i]);
}

int remove_stale_temporaries(const std::string& output, bool whole_name) noexcept {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path p(output);
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    const std::string prefix = "." + (whole_name ? p.filename() : p.stem()).string() + ".tmp";
    std::vector<fs::path> stale;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.compare(0, prefix.size(), prefix) != 0) continue;
        // ".STEM.tmp" PID, then the end or a '.' (the extension, a sidecar's extension)
        const char* first = name.c_str() + prefix.size();
        const char* last = name.c_str() + name.size();
        long pid = 0;
        const auto [stop, err] = std::from_chars(first, last, pid);
        if (err != std::errc() || stop == first || (stop != last && *stop != '.')) continue;
        if (!process_alive(pid)) stale.push_back(it->path());
    }
    int removed = 0;
    for (const auto& f : stale)
        if (fs::remove_all(f, ec) > 0) ++removed;
    return removed;
}

}  // namespace terrain::io
