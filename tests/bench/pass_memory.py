#!/usr/bin/python3
"""What each pass of the library holds: runs terrain.segment on a DEM through the Python module
(the system allocator: a freed block leaves the resident set at once, unlike the program's
kept blocks) and reads the resident set at the progress callbacks, at most every 20 ms. Prints,
for each progress message in run order, the most the process held while it was reported, in
bytes per pixel, and the fraction and second where that was (docs/performance.md, "Memory by stage").

    PYTHONPATH=build/python /usr/bin/python3 tests/bench/pass_memory.py DEM
"""
import os
import sys
import time

import terrain


def main():
    page = os.sysconf("SC_PAGE_SIZE")
    start = time.monotonic()
    last = [0.0]
    passes = {}  # message -> [most bytes, fraction, seconds]; in order of first report

    def resident():
        with open("/proc/self/statm") as statm:
            return int(statm.read().split()[1]) * page

    def report(fraction, message):
        now = time.monotonic() - start
        if now - last[0] >= 0.02:
            last[0] = now
            held = resident()
            entry = passes.setdefault(message, [0, fraction, now])
            if held > entry[0]:
                entry[:] = [held, fraction, now]
        return True

    result = terrain.segment(sys.argv[1], progress=report)
    pixels = result.labels.size
    print("pass_memory: %s, %d pixels, %d cores" % (os.path.basename(sys.argv[1]), pixels,
                                                    os.cpu_count()))
    print("%-30s %8s %9s %8s" % ("message", "B/pixel", "fraction", "second"))
    for message, (held, fraction, seconds) in passes.items():
        print("%-30s %8.1f %9.3f %8.1f" % (message, held / pixels, fraction, seconds))
    return 0


if __name__ == "__main__":
    sys.exit(main())
