// The input of the pipeline's jobs: a DEM read and meshed on its body, or a mesh file read
// (docs/architecture.md, "The pipeline's stages": read and mesh).
#include <string>

#include "stage_clock.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/mesh_files.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"
#include "terrain/pipeline/memory_plan.hpp"
#include "terrain/pipeline/segment.hpp"

namespace terrain::pipeline {

using internal::clock;
using internal::since;

Input load_input(const std::string& path, const InputOptions& options, const ProgressFn& progress) {
    const auto t0 = clock::now();
    const MemoryPlan plan =
        memory_plan(options.planned_field, options.max_memory, options.planned_segment);
    if (io::is_mesh_file(path)) {
        io::ReadMeshOptions read_options;
        read_options.repair = options.repair;
        Input input;
        input.mesh = io::read_mesh(path, read_options, progress, plan);
        input.read_seconds = since(t0);
        return input;
    }
    io::ReadDemOptions dem_options = options.dem;
    dem_options.memory = plan;
    Dem dem = io::read_dem(path, dem_options, scaled_progress(progress, 0, 0.3));
    const double read_seconds = since(t0);
    mesh::DemToMeshOptions mesh_options;
    mesh_options.frame = options.frame;
    // pipeline::segment frees the triangles of a tree before the field (below): they may go
    // before the mesh's areas and adjacency, unless the SDF is to cast rays through them.
    mesh_options.release_triangles =
        options.planned_segment && options.planned_field != field::FieldKind::sdf;
    const auto t1 = clock::now();
    Input input;
    input.mesh = mesh::dem_to_mesh(dem, mesh_options, scaled_progress(progress, 0.3, 1));
    input.mesh_seconds = since(t1);
    input.read_seconds = read_seconds;
    input.dem = std::move(dem);
    return input;
}

Input input_from_dem(Dem dem, std::optional<MeshFrame> frame, const ProgressFn& progress) {
    mesh::DemToMeshOptions mesh_options;
    mesh_options.frame = frame;
    const auto t0 = clock::now();
    Input input;
    input.mesh = mesh::dem_to_mesh(dem, mesh_options, progress);
    input.mesh_seconds = since(t0);
    input.dem = std::move(dem);
    return input;
}

}  // namespace terrain::pipeline
