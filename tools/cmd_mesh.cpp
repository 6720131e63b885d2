// terrain mesh INPUT -o OUT.ply: the georeferenced triangle mesh of a DEM, or a mesh file
// checked (and repaired on request) and written back as binary PLY.
#include <cstdio>
#include <iostream>

#include "cli.hpp"
#include "dem_options.hpp"
#include "terrain/io/mesh_files.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

namespace terrain::cli {

int run_mesh(int argc, char** argv) {
    return guarded("mesh", [&] {
        std::string input, output, frame_name = "auto";
        bool quiet = false, overwrite = false, repair = false;
        DemOptionValues dem_values;
        po::options_description options("terrain mesh options");
        options.add_options()
            ("input", po::value(&input)->required(), "a DEM (any raster GDAL opens) or a mesh "
                                                     "(.off, .ply, .obj)")
            ("output,o", po::value(&output)->required(), "the binary PLY to write")
            ("frame", po::value(&frame_name)->default_value("auto"),
             "body|map|auto: body-fixed X,Y,Z on the body, or map easting/northing/height "
             "(auto: body for planetary and geographic CRSs, map otherwise)")
            ("repair", po::bool_switch(&repair),
             "mesh input: repair degenerate or non-manifold elements instead of refusing")
            ("overwrite", po::bool_switch(&overwrite), "replace an existing output")
            ("quiet,q", po::bool_switch(&quiet), "no progress output");
        add_dem_options(options, dem_values);
        po::positional_options_description positional;
        positional.add("input", 1);
        po::variables_map vm;
        if (!parse(argc, argv, "terrain mesh INPUT -o OUT.ply [options]", options, positional, vm))
            return 0;
        mesh::DemToMeshOptions mesh_options;
        if (frame_name == "body")
            mesh_options.frame = MeshFrame::body;
        else if (frame_name == "map")
            mesh_options.frame = MeshFrame::map;
        else if (frame_name != "auto")
            throw UsageError("--frame must be body, map or auto, not '" + frame_name + "'");
        io::check_output_path(output, overwrite);

        const auto progress = terminal_progress(quiet);
        TriangleMesh mesh;
        if (io::is_mesh_file(input)) {
            io::ReadMeshOptions read_options;
            read_options.repair = repair;
            mesh = io::read_mesh(input, read_options, progress);
        } else {
            const Dem dem = io::read_dem(input, to_read_options(dem_values),
                                         scaled_progress(progress, 0.0, 0.3));
            mesh = mesh::dem_to_mesh(dem, mesh_options, scaled_progress(progress, 0.3, 1.0));
        }
        io::write_ply(mesh, output, overwrite);

        const auto topo = mesh_topology(mesh);
        double area = 0;
        for (float a : mesh.vertex_areas) area += a;
        std::printf("%s: %zu vertices, %zu triangles, %zu boundary edges in %zu loop(s), Euler "
                    "characteristic %lld, frame %s\n",
                    output.c_str(), topo.vertices, topo.faces, topo.boundary_edges,
                    topo.boundary_loops, static_cast<long long>(topo.euler_characteristic),
                    to_string(mesh.frame));
        std::printf("surface area %.6g m^2; %zu pinched vertices split, %zu isolated vertices "
                    "left out%s; %.1f bytes per vertex in memory\n",
                    area, mesh.pinched_vertices, mesh.isolated_vertices,
                    mesh.seam_closed ? "; seam closed" : "",
                    double(mesh.memory_bytes()) / double(mesh.vertex_count()));
        return 0;
    });
}

}  // namespace terrain::cli
