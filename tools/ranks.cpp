// The ranks of an MPI run (ranks.hpp): the only code of the project that calls MPI.

#include "ranks.hpp"

#include <mpi.h>

#include <chrono>
#include <climits>
#include <cstdlib>
#include <string>
#include <thread>

#include "terrain/core/error.hpp"

namespace terrain::cli {

namespace {

Ranks the_ranks;
bool started = false;

bool under_mpirun() {
    return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMIX_RANK") != nullptr;
}

// The counts and offsets of the parts (MPI's int): each part's vertices from `bounds`.
void part_counts(const std::vector<std::size_t>& bounds, std::vector<int>& counts,
                 std::vector<int>& offsets) {
    counts.clear();
    offsets.clear();
    for (std::size_t p = 0; p + 1 < bounds.size(); ++p) {
        if (bounds[p + 1] > std::size_t{INT_MAX})
            throw Error("segment", "the grid has more vertices than one MPI message holds");
        offsets.push_back(int(bounds[p]));
        counts.push_back(int(bounds[p + 1] - bounds[p]));
    }
}

void meet_ranks() {
    if (started && the_ranks.size > 1) MPI_Barrier(MPI_COMM_WORLD);
}

// The field split over the ranks: this rank's part, its values gathered with every other
// rank's.
pipeline::FieldShare field_share() {
    pipeline::FieldShare share;
    share.part = the_ranks.rank;
    share.parts = the_ranks.size;
    share.stop_after_field = the_ranks.rank != 0;
    share.gather = [](std::vector<float>& field, std::vector<std::uint8_t>& scale,
                      const std::vector<std::size_t>& bounds) {
        // (For the tests: a rank's error, after the others started their parts.)
        if (const char* fail = std::getenv("TERRAIN_FAIL_RANK");
            fail && std::string(fail) == std::to_string(the_ranks.rank))
            throw Error("segment", "stopped on purpose by TERRAIN_FAIL_RANK");
        std::vector<int> counts, offsets;
        part_counts(bounds, counts, offsets);
        MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, field.data(), counts.data(),
                       offsets.data(), MPI_FLOAT, MPI_COMM_WORLD);
        MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, scale.data(), counts.data(),
                       offsets.data(), MPI_UNSIGNED_CHAR, MPI_COMM_WORLD);
    };
    return share;
}

}  // namespace

void start_ranks(int& argc, char**& argv) {
    if (!under_mpirun()) return;
    MPI_Init(&argc, &argv);
    started = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &the_ranks.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &the_ranks.size);
}

int finish_ranks(int status) {
    if (started && the_ranks.size > 1) {
        // The ranks that end first (all but rank 0, after the field) wait for the others
        // asleep, looking every 10 ms, rather than in MPI's own waits, which spin on a core
        // rank 0 could use.
        MPI_Request all_here;
        MPI_Ibarrier(MPI_COMM_WORLD, &all_here);
        for (int done = 0;;) {
            MPI_Test(&all_here, &done, MPI_STATUS_IGNORE);
            if (done) break;
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
    }
    if (started) MPI_Finalize();
    started = false;
    return status;
}

const Ranks& ranks() {
    return the_ranks;
}

void stop_all_ranks(int status) {
    if (started && the_ranks.size > 1) MPI_Abort(MPI_COMM_WORLD, status);
}

void RankedCommand::reading() const {
    if (!writer()) meet_ranks();
}

void RankedCommand::read() const {
    if (writer()) meet_ranks();
}

bool RankedCommand::take_part(pipeline::SegmentOptions& options,
                              const pipeline::Input& input) const {
    return take_part(options.field_share, pipeline::field_splits(options, input));
}

bool RankedCommand::take_part(pipeline::FieldShare& share, bool splits) const {
    if (the_ranks.size > 1 && splits) {
        share = field_share();
        return true;
    }
    return writer();
}

}  // namespace terrain::cli
