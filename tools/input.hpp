#pragma once
// The input every mesh-based subcommand takes: a DEM (read, then triangulated on its body)
// or a mesh file, with the options that control both.

#include <optional>
#include <string>

#include "cli.hpp"
#include "dem_options.hpp"
#include "terrain/field/field_kind.hpp"
#include "terrain/pipeline/segment.hpp"

namespace terrain::cli {

struct InputOptionValues {
    DemOptionValues dem;
    std::string frame = "auto";
    bool repair = false;
};

// Adds the DEM options plus --frame and --repair.
void add_input_options(po::options_description& options, InputOptionValues& values);

using Input = pipeline::Input;

// Reads `path` as a mesh file (.off/.ply/.obj) or a DEM and builds the mesh
// (pipeline::load_input, with the options checked and the memory planned for computing
// `field` next, none for meshing only, and `segment` for pipeline::segment's own plan;
// --max-memory).
Input load_input(const std::string& path, const InputOptionValues& values,
                 std::optional<field::FieldKind> field, const ProgressFn& progress,
                 bool segment = false);

}  // namespace terrain::cli
