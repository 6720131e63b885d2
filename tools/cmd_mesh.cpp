// terrain mesh INPUT -o OUT.ply: the georeferenced triangle mesh of a DEM, or a mesh file
// checked (and repaired on request) and written back as binary PLY.
#include <cstdio>
#include <iostream>

#include "cli.hpp"
#include "input.hpp"
#include "terrain/io/mesh_files.hpp"
#include "terrain/io/output_file.hpp"

namespace terrain::cli {

int run_mesh(int argc, char** argv) {
    return guarded("mesh", [&] {
        std::string input_path, output;
        bool quiet = false, overwrite = false;
        InputOptionValues input_values;
        po::options_description options("terrain mesh options");
        options.add_options()("input", po::value(&input_path)->required(),
                              "a DEM (any raster GDAL opens) or a mesh (.off, .ply, .obj)")(
            "output,o", po::value(&output)->required(), "the binary PLY to write")(
            "overwrite", po::bool_switch(&overwrite), "replace an existing output")(
            "quiet,q", po::bool_switch(&quiet), "no progress output");
        add_input_options(options, input_values);
        po::positional_options_description positional;
        positional.add("input", 1);
        po::variables_map vm;
        if (!parse(argc, argv, "terrain mesh INPUT -o OUT.ply [options]", options, positional, vm))
            return 0;
        io::check_output_path(output, overwrite);
        const TriangleMesh mesh =
            load_input(input_path, input_values, std::nullopt, terminal_progress(quiet)).mesh;
        io::write_ply(mesh, output, overwrite);

        const auto topo = mesh_topology(mesh);
        double area = 0;
        for (float a : mesh.vertex_areas) area += a;
        std::printf(
            "%s: %zu vertices, %zu triangles, %zu boundary edges in %zu loop(s), Euler "
            "characteristic %lld, frame %s\n",
            output.c_str(), topo.vertices, topo.faces, topo.boundary_edges, topo.boundary_loops,
            static_cast<long long>(topo.euler_characteristic), to_string(mesh.frame));
        std::printf(
            "surface area %.6g m^2; %zu pinched vertices split, %zu isolated vertices "
            "left out%s; %.1f bytes per vertex in memory\n",
            area, mesh.pinched_vertices, mesh.isolated_vertices,
            mesh.seam_closed ? "; seam closed" : "",
            double(mesh.memory_bytes()) / double(mesh.vertex_count()));
        return 0;
    });
}

}  // namespace terrain::cli
