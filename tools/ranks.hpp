#pragma once
// The ranks of an MPI run: `mpirun -np N terrain segment ...` (docs/scale.md, "Ranks"). The one
// `terrain` program runs under mpirun or without it: MPI starts only when the process was
// started by mpirun, so a run without it is one process, as always.

#include "terrain/pipeline/segment.hpp"

namespace terrain::cli {

struct Ranks {
    int rank = 0, size = 1;
};

// Starts MPI when mpirun started this process (Open MPI's OMPI_COMM_WORLD_SIZE, or PMIx's
// PMIX_RANK, in the environment).
void start_ranks(int& argc, char**& argv);
// Ends MPI when it was started; returns `status`.
int finish_ranks(int status);
const Ranks& ranks();

// With several ranks: stops every rank with `status` (after a rank's error line).
void stop_all_ranks(int status);

// The field split over the ranks (pipeline::FieldShare): this rank's part, its values
// gathered with every other rank's.
pipeline::FieldShare field_share();

// With several ranks, a meeting of all: rank 0 comes once it has checked the output and read
// the input, the others before reading it, so that an error every rank would meet (a bad
// input or output) is reported once, by rank 0, which then stops them all.
void meet_ranks();

}  // namespace terrain::cli
