#!/usr/bin/env python3
"""Benchmark: `terrain segment` end to end on global equirectangular DEMs of Vesta
(cratered, radii in 2 m steps like the HAMO DNs; make_global_dem.py beside this file) at
several sizes. Prints, per size, the wall time and the peak memory (bytes per pixel), then
seconds per million pixels for each stage, so that the growth of the cost with size shows.

  bench_global.py [BUILD_DIR] [WIDTH ...]      (height = width / 2)

Widths: 1440 (1 M pixels), 5760 (16 M), 11520 (66 M), 23040 (265 M). Default: 1440 2880."""
import json
import os
import subprocess
import sys
import tempfile

STAGES = ["read", "mesh", "field", "reeb", "simplify", "grow", "write"]


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    widths = [int(w) for w in sys.argv[2:]] or [1440, 2880]
    terrain = os.path.join(build, "tools", "terrain")
    here = os.path.dirname(os.path.abspath(__file__))
    print(f"{'pixels':<12} {'wall_s':>8} {'peak_MiB':>9} {'B/pixel':>8} {'s/Mpx':>7} "
          + " ".join(f"{s:>8}" for s in STAGES) + f"   ({os.cpu_count()} cores; stages in s/Mpx)")
    with tempfile.TemporaryDirectory() as work:
        for w in widths:
            h = w // 2
            dem = os.path.join(work, "dem.tif")
            subprocess.run([sys.executable, os.path.join(here, "make_global_dem.py"), dem, str(w)],
                           check=True, stderr=subprocess.DEVNULL)
            out, timing = os.path.join(work, "out"), os.path.join(work, "time")
            subprocess.run(["rm", "-rf", out], check=True)
            subprocess.run(["/usr/bin/time", "-f", "%e %M", "-o", timing, terrain, "segment", "-q",
                            dem, "-o", out, "--timings"], check=True, stdout=subprocess.DEVNULL)
            wall, rss_kb = open(timing).read().split()[-2:]
            wall, rss = float(wall), int(rss_kb) * 1024
            px = w * h
            mpx = px / 1e6
            t = json.load(open(os.path.join(out, "run.json")))["timings_seconds"]
            print(f"{w}x{h:<7} {wall:8.1f} {rss / 2**20:9.0f} {rss / px:8.0f} {wall / mpx:7.2f} "
                  + " ".join(f"{t.get(s, 0) / mpx:8.2f}" for s in STAGES), flush=True)
            os.remove(dem)


if __name__ == "__main__":
    main()
