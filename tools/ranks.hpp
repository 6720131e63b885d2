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

// A command whose field splits over the ranks (segment, sweep): rank 0 checks the output,
// reads the input and meets the others, which read the input only then (so that an error
// every rank would meet, a bad input or output, is one line from rank 0, which then stops
// them all); each rank makes its band of the field, and rank 0 alone goes on and writes.
class RankedCommand {
  public:
    // Whether this rank checks, reports and writes (rank 0, or the only process).
    bool writer() const { return ranks().rank == 0; }
    // Before reading the input (after rank 0 checked the output), and after it.
    void reading() const;
    void read() const;
    // options.field_share set when the field of `input` splits over the ranks; false when
    // this rank has no part in the run (the field does not split: rank 0 makes it whole).
    bool take_part(pipeline::SegmentOptions& options, const pipeline::Input& input) const;
    // The same for a field that splits when `splits`, into `share`.
    bool take_part(pipeline::FieldShare& share, bool splits) const;
};

}  // namespace terrain::cli
