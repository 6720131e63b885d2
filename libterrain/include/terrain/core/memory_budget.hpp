#pragma once
// A memory budget checked before large allocations: the expected peak of a stage, estimated
// from declared sizes, against the memory available (MemAvailable of /proc/meminfo) and an
// optional limit, so that input lying about its size costs one error line, not the system.

#include <cstdint>
#include <optional>
#include <string>

namespace terrain {

// Bytes the system can give without swapping (MemAvailable), or nullopt when unknown.
std::optional<std::uint64_t> available_memory();

// A limit of its own (e.g. from --max-memory); 0 removes it. Process-wide.
void set_memory_limit(std::uint64_t bytes);
std::uint64_t memory_limit();

// Parses "512M", "4G", "1.5GB", "100000" (bytes); throws terrain::Error on anything else.
std::uint64_t parse_memory_size(const std::string& text);

// "3.2 GB", "512 MB", "900 B"
std::string format_bytes(double bytes);

// Throws terrain::Error (stage "memory") when `bytes` exceed the limit or the memory
// available; `what` names the work ("reading a 20000x20000 DEM").
void check_memory(const std::string& what, double bytes);

}  // namespace terrain
