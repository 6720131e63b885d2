// The main job through the library: segment a DEM tile with the paper's terrain parameters.
//   segment_tile DEM OUTDIR
#include <cstdio>
#include <filesystem>

#include "terrain/core/error.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/io/write_segment_outputs.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/reeb/simplify.hpp"
#include "terrain/segment/grow_regions.hpp"

int run(const char* dem_path, const char* out_dir) {
    using namespace terrain;
    const Dem dem = io::read_dem(dem_path);
    const TriangleMesh mesh = mesh::dem_to_mesh(dem);                // on the body, in metres
    const auto field = field::shape_index_field(mesh);               // shape index x100
    const auto graph = reeb::build_reeb_graph(mesh, field);          // exact Reeb graph
    const auto simple = reeb::simplify(mesh, graph, {10, 0.5});      // persistence 10, area 0.5 %
    const auto regions = segment::grow_regions(mesh, simple.graph);  // graph cost, lambda 20
    const auto rg = segment::region_graph(mesh, field, regions.labels, regions.region_count, &dem);
    std::filesystem::create_directories(out_dir);
    for (const auto& path :
         io::write_segment_outputs(out_dir, mesh, field, regions.labels, rg, &dem))
        std::printf("%s\n", path.c_str());
    std::printf("%u regions\n", regions.region_count);
    return 0;
}

int main(int argc, char** argv) {
    if (argc != 3) return std::fprintf(stderr, "usage: segment_tile DEM OUTDIR\n"), 2;
    try {
        return run(argv[1], argv[2]);
    } catch (const terrain::Error& e) {
        return std::fprintf(stderr, "segment_tile: %s\n", e.what()), 1;
    }
}
