#pragma once
// The memory plan of the pipeline: the expected peak of reading an input and computing a
// field, a Reeb graph and the segmentation on it, from the input's declared size, so that
// every caller (the command line, the Python module, the QGIS provider) refuses the same
// input with the same line before anything large is read (docs/robustness.md, "Memory
// budget", gives the measurements the figures come from).

#include <cstdint>
#include <optional>

#include "terrain/core/memory_budget.hpp"
#include "terrain/field/field_kind.hpp"

namespace terrain::pipeline {

// The plan of reading an input and working on it with `field` (unset for reading and meshing
// only, as `terrain mesh` does), with the caller's limit in bytes (0: the memory available
// only). `segment`: the work is pipeline::segment (one scale), which frees and parks on disk
// what its stages do not read, so a DEM costs less than the field, the Reeb graph or a sweep
// over scales, which hold them.
MemoryPlan memory_plan(std::optional<field::FieldKind> field, std::uint64_t limit = 0,
                       bool segment = false);

}  // namespace terrain::pipeline
