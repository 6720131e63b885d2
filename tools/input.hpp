#pragma once
// The input every mesh-based subcommand takes: a DEM (read, then triangulated on its body)
// or a mesh file, with the options that control both.

#include <optional>
#include <string>

#include "cli.hpp"
#include "dem_options.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::cli {

struct InputOptionValues {
    DemOptionValues dem;
    std::string frame = "auto";
    bool repair = false;
};

// Adds the DEM options plus --frame and --repair.
void add_input_options(po::options_description& options, InputOptionValues& values);

struct Input {
    std::optional<Dem> dem;  // set for DEM input
    TriangleMesh mesh;
    double read_seconds = 0, mesh_seconds = 0;  // wall time of reading and triangulating
};

// Reads `path` as a mesh file (.off/.ply/.obj) or a DEM and builds the mesh.
Input load_input(const std::string& path, const InputOptionValues& values,
                 const ProgressFn& progress);

}  // namespace terrain::cli
