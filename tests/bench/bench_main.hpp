#pragma once
// Every benchmark's main: --help (or -h) prints what it measures and how to call it; a bad
// argument or any failure is one line on stderr and exit status 1, never an uncaught
// exception.

#include <cstdio>
#include <cstring>
#include <exception>

namespace terrain::bench {

template <class Run>
int bench_main(int argc, char** argv, const char* usage, Run&& run) {
    for (int i = 1; i < argc; ++i)
        if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
            std::printf("%s\n", usage);
            return 0;
        }
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s (--help for the usage)\n", argv[0], e.what());
        return 1;
    }
}

}  // namespace terrain::bench
