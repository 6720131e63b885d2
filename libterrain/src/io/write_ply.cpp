#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>

#include "terrain/core/error.hpp"
#include "terrain/core/version.hpp"
#include "terrain/io/mesh_files.hpp"
#include "terrain/io/output_file.hpp"

namespace terrain::io {
namespace {

// PLY binary_little_endian stores values as they are in memory on x86/ARM little-endian.
template <class T>
void put(std::ofstream& out, T value) {
    static_assert(std::endian::native == std::endian::little, "big-endian hosts need swapping");
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out.write(bytes, sizeof(T));
}

}  // namespace

void write_ply(const TriangleMesh& mesh, const std::string& path, bool overwrite,
               const std::vector<VertexProperty>& extra) {
    const std::size_t n = mesh.vertex_count();
    for (const auto& property : extra)
        if (property.labels ? property.labels->size() != n
                            : (!property.values || property.values->size() != n))
            throw Error("write", "property '" + property.name + "' has the wrong number of values");
    // No NaN written as if it were a coordinate or an area (what a grid off its body gave
    // before io::read_dem refused it): the stage that made them missed a fault of the input.
    for (std::size_t v = 0; v < n; ++v) {
        const auto p = mesh.position(v);
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]) ||
            (v < mesh.vertex_areas.size() && !std::isfinite(mesh.vertex_areas[v])))
            throw Error("write", "vertex " + std::to_string(v) + " of the mesh for '" + path +
                                     "' has a NaN or infinite position or area; nothing is "
                                     "written (check the input's CRS radius, geotransform "
                                     "and values)");
    }
    AtomicOutput output(path, overwrite);
    {
        std::ofstream out(output.temp_path(), std::ios::binary);
        if (!out) throw Error("write", "cannot create '" + path + "'");
        const bool pixels = !mesh.vertex_pixel.empty() && mesh.grid_width > 0;
        out << "ply\nformat binary_little_endian 1.0\n";
        out << "comment made by terrain " << version() << "\n";
        out << "comment frame " << to_string(mesh.frame);
        if (!mesh.body.name.empty() && mesh.body.has_crs)
            out << " body " << mesh.body.name << " a " << mesh.body.semi_major_axis << " f "
                << mesh.body.flattening;
        out << "\n";
        out << "element vertex " << n << "\n";
        out << "property double x\nproperty double y\nproperty double z\n";
        if (pixels) out << "property int col\nproperty int row\n";
        out << "property float area\n";
        for (const auto& property : extra)
            out << "property " << (property.labels ? "uint " : "float ") << property.name << "\n";
        out << "element face " << mesh.triangle_count() << "\n";
        out << "property list uchar int vertex_indices\nend_header\n";
        for (std::size_t v = 0; v < n; ++v) {
            const auto p = mesh.position(v);
            put(out, p[0]);
            put(out, p[1]);
            put(out, p[2]);
            if (pixels) {
                put(out, std::int32_t(mesh.vertex_pixel[v] % mesh.grid_width));
                put(out, std::int32_t(mesh.vertex_pixel[v] / mesh.grid_width));
            }
            put(out, mesh.vertex_areas[v]);
            for (const auto& property : extra) {
                if (property.labels)
                    put(out, (*property.labels)[v]);
                else
                    put(out, (*property.values)[v]);
            }
        }
        for (const auto& t : mesh.triangles()) {
            put(out, std::uint8_t{3});
            for (auto v : t) put(out, v);
        }
        out.flush();
        if (!out) throw Error("write", "writing '" + path + "' failed (disk full?)");
    }
    output.commit();
}

}  // namespace terrain::io
