#pragma once
// Mesh files checked before a third-party parser sees them: the header must be well formed
// and every declared count (vertices, faces, list lengths) must fit in the bytes the file
// holds, so that a lying header costs one error line instead of a crash or gigabytes.
#include <cstdint>
#include <string>
#include <string_view>

namespace terrain::io {

// Largest magnitude of a mesh coordinate (metres: a million kilometres).
constexpr double kMaxMeshCoordinate = 1e9;

struct MeshFileCounts {
    std::uint64_t vertices = 0;  // declared vertices
    std::uint64_t faces = 0;     // declared faces
    std::uint64_t indices = 0;   // face corner indices, summed over the faces (0: not counted)
};

// Checks the bytes of a .ply, .off or .obj file (`extension` lower case, with its dot).
// Throws terrain::Error (stage "mesh") naming the first problem; `name` is used in messages.
MeshFileCounts check_mesh_bytes(std::string_view bytes, const std::string& extension,
                                const std::string& name);

// The same on a file, mapped read-only.
MeshFileCounts check_mesh_file(const std::string& path, const std::string& extension);

}  // namespace terrain::io
