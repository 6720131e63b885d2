#pragma once
// The benchmarks' measures: the best wall time of a few runs with its CPU time, and the
// process's resident set from /proc/self/status.

#include <time.h>

#include <chrono>
#include <fstream>
#include <string>

namespace terrain::bench {

inline double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Best wall time of a few runs, and the CPU time of that run (on a busy machine the CPU time
// is the better measure of a single-threaded step).
template <class F>
double best_of(int runs, F&& f, double* cpu) {
    double best = 1e300;
    for (int i = 0; i < runs; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        const double c0 = thread_cpu_seconds();
        f();
        const double wall =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (wall < best) {
            best = wall;
            *cpu = thread_cpu_seconds() - c0;
        }
    }
    return best;
}

// kB of the process's resident set ("VmRSS") or of its peak ("VmHWM").
inline double status_kb(const char* key) {
    std::ifstream in("/proc/self/status");
    std::string k;
    double value = 0;
    while (in >> k) {
        if (k == std::string(key) + ":") {
            in >> value;
            return value;
        }
        std::getline(in, k);
    }
    return 0;
}

}  // namespace terrain::bench
