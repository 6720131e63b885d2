#include "terrain/core/memory_budget.hpp"

#include <malloc.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "terrain/core/error.hpp"

namespace terrain {
namespace {
std::atomic<std::uint64_t> limit_bytes{0};
std::atomic<void (*)()> free_memory_release{nullptr};
}  // namespace

void set_free_memory_release(void (*release)()) {
    free_memory_release = release;
}

void release_free_memory() {
    if (const auto release = free_memory_release.load()) release();
    malloc_trim(0);
}

std::optional<std::uint64_t> available_memory() {
    std::ifstream in("/proc/meminfo");
    std::string key, unit;
    std::uint64_t value = 0;
    while (in >> key >> value) {
        std::getline(in, unit);
        if (key == "MemAvailable:") return value * 1024;
    }
    return std::nullopt;
}

void set_memory_limit(std::uint64_t bytes) {
    limit_bytes = bytes;
}

std::uint64_t memory_limit() {
    return limit_bytes;
}

std::uint64_t parse_memory_size(const std::string& text) {
    std::istringstream in(text);
    double value = 0;
    std::string unit;
    if (!(in >> value) || !std::isfinite(value) || value <= 0)
        throw Error("memory", "'" + text + "' is not a memory size; give e.g. 512M or 4G");
    in >> unit;
    for (auto& c : unit) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (unit.size() == 2 && unit[1] == 'B') unit.pop_back();
    double factor = 1;
    if (unit == "" || unit == "B")
        factor = 1;
    else if (unit == "K")
        factor = 1024.0;
    else if (unit == "M")
        factor = 1024.0 * 1024;
    else if (unit == "G")
        factor = 1024.0 * 1024 * 1024;
    else if (unit == "T")
        factor = 1024.0 * 1024 * 1024 * 1024;
    else
        throw Error("memory", "'" + text + "' is not a memory size; give e.g. 512M or 4G");
    std::string rest;
    if (in >> rest || value * factor > 1.8e19)
        throw Error("memory", "'" + text + "' is not a memory size; give e.g. 512M or 4G");
    return static_cast<std::uint64_t>(value * factor);
}

std::string format_bytes(double bytes) {
    char text[64];
    const char* units[] = {"B", "KB", "MB", "GB", "TB", "PB", "EB"};
    int u = 0;
    while (bytes >= 1024 && u < 6) {
        bytes /= 1024;
        ++u;
    }
    std::snprintf(text, sizeof text, u == 0 ? "%.0f %s" : "%.3g %s", bytes, units[u]);
    return text;
}

namespace {
std::string bytes_text(double bytes) {
    char exact[32];
    std::snprintf(exact, sizeof exact, "%.0f", std::ceil(bytes));
    return format_bytes(bytes) + " (" + exact + " bytes)";
}
}  // namespace

void check_memory(const std::string& what, double bytes, std::uint64_t limit, double held) {
    if (limit == 0) limit = limit_bytes;
    if (limit > 0 && bytes > double(limit))
        throw Error("memory", what + " needs about " + bytes_text(bytes) +
                                  " but the memory limit is " + bytes_text(double(limit)));
    // What the process holds already is part of `bytes` and not of the memory available.
    if (const auto available = available_memory(); available && bytes > double(*available) + held)
        throw Error("memory", what + " needs about " + bytes_text(bytes) + " but only " +
                                  bytes_text(double(*available) + held) +
                                  " are available; use a smaller input or free memory");
}

}  // namespace terrain
