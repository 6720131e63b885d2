#include "terrain/core/error.hpp"
#include "terrain/io/mesh_files.hpp"
#include "terrain/io/write_mesh_labels.hpp"

namespace terrain::io {

void write_labels_ply(const TriangleMesh& mesh, const std::vector<float>& field,
                      const std::vector<std::uint32_t>& labels, const std::string& path,
                      bool overwrite, const std::string& field_name) {
    if (field_name.empty() || field_name == "label")
        throw Error("write", "the field needs a name other than 'label' in '" + path + "'");
    write_ply(mesh, path, overwrite,
              {VertexProperty{"label", nullptr, &labels}, VertexProperty{field_name, &field}});
}

}  // namespace terrain::io
