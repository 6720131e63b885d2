#!/usr/bin/python3
"""How often the library's progress moves: runs terrain.segment on a DEM through the Python
module and prints the longest silences between two callback calls, with the stages on each
side, and whether the fraction ever went back (docs/performance.md, "Progress on long runs").

    PYTHONPATH=build/python /usr/bin/python3 tests/bench/progress_gaps.py DEM [COUNT]
"""
import os
import sys
import time

import terrain


def main():
    path = sys.argv[1]
    count = int(sys.argv[2]) if len(sys.argv) > 2 else 10
    start = time.monotonic()
    last = {"at": start, "fraction": 0.0, "message": "start"}
    gaps, back, calls = [], 0, 0

    def callback(fraction, message):
        nonlocal back, calls
        now = time.monotonic()
        calls += 1
        gaps.append((now - last["at"], now - start, last["message"], message, last["fraction"],
                     fraction))
        if fraction < last["fraction"] - 1e-12:
            back += 1
        last.update(at=now, fraction=fraction, message=message)
        return True

    result = terrain.segment(path, progress=callback)
    total = time.monotonic() - start
    print("progress_gaps: %s, %d cores, %d regions, %.1f s, %d calls, %d going back"
          % (os.path.basename(path), os.cpu_count(), result.region_count, total, calls, back))
    for gap in sorted(gaps, reverse=True)[:count]:
        print("  %.2f s silent at %.1f s: %s (%.4f) -> %s (%.4f)"
              % (gap[0], gap[1], gap[2], gap[4], gap[3], gap[5]))
    return 1 if back else 0


if __name__ == "__main__":
    sys.exit(main())
