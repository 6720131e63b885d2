
#include "dataset_files.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/write_mesh_labels.hpp"

namespace terrain::io {

std::vector<std::uint32_t> face_labels(const TriangleMesh& mesh,
                                       const std::vector<std::uint32_t>& labels) {
    if (labels.size() != mesh.vertex_count())
        throw Error("write", "face labels need one label per mesh vertex");
    std::vector<std::uint32_t> out;
    out.reserve(mesh.triangle_count());
    for (const auto& t : mesh.triangles()) {
        const auto a = labels[std::size_t(t[0])], b = labels[std::size_t(t[1])],
                   c = labels[std::size_t(t[2])];
        // Two equal labels are the majority; three different ones go to the lowest.
        out.push_back(a == b || a == c ? a : (b == c ? b : std::min({a, b, c})));
    }
    return out;
}

void write_faces_seg(const TriangleMesh& mesh, const std::vector<std::uint32_t>& labels,
                     const std::string& path, bool overwrite) {
    const auto faces = face_labels(mesh, labels);
    write_file_atomically(path, overwrite, [&](std::ostream& out) {
        for (auto label : faces) out << label << '\n';
    });
}

}  // namespace terrain::io
