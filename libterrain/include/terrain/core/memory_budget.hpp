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

// Memory the process keeps freed for reuse, given back to the system: glibc's free pages
// (malloc_trim) and what the program registered here (the terrain program keeps its large
// freed blocks for the next large allocation, tools/big_blocks.cpp). The pipeline calls it
// before writing outputs, whose libraries allocate on their own, and once its large arrays
// are freed.
void set_free_memory_release(void (*release)());
void release_free_memory();

// Parses "512M", "4G", "1.5GB", "100000" (bytes); throws terrain::Error on anything else.
std::uint64_t parse_memory_size(const std::string& text);

// "3.2 GB", "512 MB", "900 B"
std::string format_bytes(double bytes);

// The expected peak of reading an input and of the work planned on it: a fixed part (the
// process with GDAL, PROJ, CGAL and the thread pool) plus parts proportional to the DEM's
// pixels (the grids: values, labels) and valid pixels (the mesh and all that follows), or to
// the mesh file's vertices, faces and face corners; for a DEM at least `floor_bytes` (a stage
// whose peak does not grow with the input: encoding the preview). pipeline::memory_plan gives
// the plan of each field (docs/robustness.md).
struct MemoryPlan {
    double floor_bytes = 0;
    double base_bytes = 0;
    double bytes_per_pixel = 8;  // the grid of doubles alone
    double bytes_per_valid_pixel = 0;
    double bytes_per_vertex = 200, bytes_per_face = 300, bytes_per_corner = 16;  // reading
    std::uint64_t limit = 0;  // bytes; 0: the process-wide limit, if any (set_memory_limit)
    bool checked = true;      // false: no check (reading a DEM one row at a time)

    double dem_bytes(double pixels, double valid_pixels) const {
        const double grows =
            base_bytes + bytes_per_pixel * pixels + bytes_per_valid_pixel * valid_pixels;
        return grows > floor_bytes ? grows : floor_bytes;
    }
    double mesh_bytes(double vertices, double faces, double corners) const {
        return base_bytes + bytes_per_vertex * vertices + bytes_per_face * faces +
               bytes_per_corner * corners;
    }
};

// Throws terrain::Error (stage "memory") when `bytes` exceed the limit or the memory
// available; `what` names the work ("the 20000x20000 grid of 'x.tif'"). `limit`: the
// caller's own limit in bytes (pipeline::InputOptions::max_memory); 0 takes the
// process-wide one of set_memory_limit, if any. The one line names the bytes needed and
// the bytes the limit or the system allows, rounded and exact:
//   "... needs about 152 MB (159383552 bytes) but the memory limit is 140 MB (146800640 bytes)"
// `held`: bytes of `bytes` the process holds already (a DEM read before its valid pixels
// are counted), which the memory available no longer includes.
void check_memory(const std::string& what, double bytes, std::uint64_t limit = 0, double held = 0);

}  // namespace terrain
