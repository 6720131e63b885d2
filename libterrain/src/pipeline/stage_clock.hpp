#pragma once
// Private: the clock the pipeline's stages are timed with (run.json's timings_seconds).
#include <chrono>

namespace terrain::pipeline::internal {

using clock = std::chrono::steady_clock;

// The seconds since t0.
inline double since(clock::time_point t0) {
    return std::chrono::duration<double>(clock::now() - t0).count();
}

}  // namespace terrain::pipeline::internal
