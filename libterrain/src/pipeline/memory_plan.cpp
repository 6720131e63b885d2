#include "terrain/pipeline/memory_plan.hpp"

namespace terrain::pipeline {
namespace {
constexpr double MB = 1024.0 * 1024.0;
}  // namespace

// Fitted to the peak resident memory (/usr/bin/time -v) of `terrain mesh` and `terrain
// segment` on the samples and shared DEMs (8 400 to 1 036 800 pixels) and on meshes written
// from them (8 400 to 1 033 922 vertices, two faces a vertex), with a margin of about 25 %
// over the measured slope; the table is in docs/robustness.md.
MemoryPlan memory_plan(std::optional<field::FieldKind> field, std::uint64_t limit, bool segment) {
    MemoryPlan plan;
    plan.limit = limit;
    plan.bytes_per_corner = 0;  // counted in the faces (triangles)
    // Mesh files: reading the polygon soup dominates (about 420 bytes a vertex measured
    // for the shape index, 500 for the SDF).
    plan.base_bytes = 50 * MB;
    plan.bytes_per_vertex = 130;
    plan.bytes_per_face = 200;
    const bool sdf = field == field::FieldKind::sdf;
    if (sdf) {
        plan.bytes_per_vertex = 150;
        plan.bytes_per_face = 240;
    }
    // DEMs: the grids (the values as doubles, the pixels' vertices, the labels) cost 16 to 24
    // bytes a pixel; the rest goes with the valid pixels. Measured on fully valid grids
    // (global synthetic grids of 1 to 66 M pixels): 80 bytes a pixel for reading and
    // meshing; 79 to 81 for `segment` with the shape index or the height from 16.6 M pixels
    // on (the positions freed and the large arrays the Reeb graph and the simplification do
    // not read parked on disk; below that the process's own memory and the preview, encoded
    // after the large data are freed, make a floor of about 176 MB); up to 116 for the field,
    // the Reeb graph and a sweep, which hold them (the sweep keeps the Reeb graph beside each
    // scale's working graph); 545 with the SDF.
    if (!field) {
        plan.bytes_per_pixel = 16;
        plan.bytes_per_valid_pixel = 84;
    } else {
        plan.floor_bytes = 200 * MB;
        plan.bytes_per_pixel = 24;
        plan.bytes_per_valid_pixel = sdf ? 656 : (segment ? 62 : 116);
    }
    return plan;
}

}  // namespace terrain::pipeline
