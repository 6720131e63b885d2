#!/usr/bin/env python3
"""Benchmark: `terrain segment` end to end on global equirectangular DEMs of Vesta
(cratered, radii in 2 m steps like the HAMO DNs; make_global_dem.py beside this file) at
several sizes. Prints, per size, the wall time and the peak memory (bytes per pixel), then
seconds per million pixels for each stage, so that the growth of the cost with size shows;
`x_first` is a size's seconds per Mpx over the first size's (the run's linearity: 1.3 at most
is asked of the 265 M grid against the 1 M one). The first size runs three times, and its
median is the reference. A second line per run gives the CPU seconds per wall second, of the
whole run (`cpu/wall`) and of each stage: the process's CPU time sampled every 0.1 s, each
stage's share read between its start and end as run.json's timings place them (from the
process's start; a stage under a second is too short to read and shows `-`).

  bench_global.py [BUILD_DIR] [WIDTH ...]      (height = width / 2)

Widths: 1440 (1 M pixels), 5760 (16 M), 11520 (66 M), 23040 (265 M). Default: 1440 2880."""
import json
import os
import statistics
import subprocess
import sys
import tempfile

from stage_samples import run_sampled, stage_spans

STAGES = ["read", "mesh", "field", "reeb", "simplify", "grow", "write"]
FIRST_RUNS = 3


def cpu_seconds(pid):
    """The CPU seconds (user + system) process pid has used so far; None when it cannot be
    read."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def run(terrain, dem, work):
    """`terrain segment` with every output: wall seconds, peak resident bytes, stage seconds,
    the CPU seconds per wall second of the run and of each stage (None: too short to read)."""
    out = os.path.join(work, "out")
    subprocess.run(["rm", "-rf", out], check=True)
    process, wall, usage, samples = run_sampled(
        [terrain, "segment", "-q", dem, "-o", out, "--timings"], cpu_seconds, 0.1,
        stdout=subprocess.DEVNULL)
    if process.returncode != 0:
        raise subprocess.CalledProcessError(process.returncode, terrain)
    t = json.load(open(os.path.join(out, "run.json")))["timings_seconds"]
    cores = {"cpu/wall": (usage.ru_utime + usage.ru_stime) / max(wall, 1e-9)}
    for stage, begin, end in stage_spans(t, 0.0):
        inside = [s for s in samples if begin <= s[0] <= end]
        cores[stage] = ((inside[-1][1] - inside[0][1]) / (inside[-1][0] - inside[0][0])
                        if len(inside) >= 10 else None)
    return wall, usage.ru_maxrss * 1024, t, cores


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    widths = [int(w) for w in sys.argv[2:]] or [1440, 2880]
    terrain = os.path.join(build, "tools", "terrain")
    here = os.path.dirname(os.path.abspath(__file__))
    print(f"{'pixels':<12} {'wall_s':>8} {'peak_MiB':>9} {'B/pixel':>8} {'s/Mpx':>7} {'x_first':>7} "
          + " ".join(f"{s:>8}" for s in STAGES) + f"   ({os.cpu_count()} cores; stages in s/Mpx)")
    first = None  # the first size's median seconds per Mpx
    with tempfile.TemporaryDirectory() as work:
        for i, w in enumerate(widths):
            h = w // 2
            dem = os.path.join(work, "dem.tif")
            subprocess.run([sys.executable, os.path.join(here, "make_global_dem.py"), dem, str(w)],
                           check=True, stderr=subprocess.DEVNULL)
            # The first size is small, and its time varies by a third from run to run: it runs
            # FIRST_RUNS times, and the median of its seconds per Mpx is what x_first divides by.
            px = w * h
            mpx = px / 1e6
            rates = []
            for _ in range(FIRST_RUNS if i == 0 else 1):
                wall, rss, t, cores = run(terrain, dem, work)
                rates.append(wall / mpx)
                ratio = f"{wall / mpx / first:7.2f}" if first else f"{'':7}"
                print(f"{w}x{h:<7} {wall:8.1f} {rss / 2**20:9.0f} {rss / px:8.0f} {wall / mpx:7.2f} "
                      f"{ratio} " + " ".join(f"{t.get(s, 0) / mpx:8.2f}" for s in STAGES), flush=True)
                share = " ".join(f"{cores[s]:8.2f}" if cores.get(s) is not None else f"{'-':>8}"
                                 for s in STAGES)
                print(f"{'':12} {'cpu/wall':>26} {cores['cpu/wall']:7.2f} {'':7} {share}",
                      flush=True)
            if first is None:
                first = statistics.median(rates)
                print(f"{'':12} (the first size's median: {first:.2f} s/Mpx)", flush=True)
            os.remove(dem)


if __name__ == "__main__":
    main()
