// libFuzzer target: one mesh reader (TERRAIN_FUZZ_EXTENSION: ".ply", ".off" or ".obj") on
// arbitrary bytes. A refusal is a terrain::Error; anything else (a crash, a leak, a hang,
// undefined behaviour, memory beyond -rss_limit_mb) is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "terrain/core/error.hpp"
#include "terrain/io/mesh_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    // CGAL's readers take a path: one file per process, rewritten for each input.
    static const std::string path =
        "/tmp/terrain_fuzz_" + std::to_string(::getpid()) + TERRAIN_FUZZ_EXTENSION;
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    }
    for (bool repair : {false, true}) {
        try {
            terrain::io::ReadMeshOptions options;
            options.repair = repair;
            (void)terrain::io::read_mesh(path, options);
        } catch (const terrain::Error&) {
        }
    }
    return 0;
}
