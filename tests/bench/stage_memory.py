#!/usr/bin/python3
"""The peak resident set of each stage of `terrain segment`: runs it, samples its resident set
every 50 ms and splits the samples by the stage times run.json reports (docs/performance.md,
"Memory by stage"). The stages' edges are approximate by the sampling period.

    /usr/bin/python3 tests/bench/stage_memory.py BUILD DEM OUTDIR [terrain segment options]
"""
import json
import os
import subprocess
import sys

from stage_samples import run_sampled, stage_spans


def resident_mib(pid):
    """The resident set of process pid in MiB; None when it cannot be read."""
    try:
        with open("/proc/%d/status" % pid) as status:
            for line in status:
                if line.startswith("VmRSS"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return None


def main():
    build, dem, out = sys.argv[1:4]
    command = [os.path.join(build, "tools", "terrain"), "segment", dem, "-o", out, "-q",
               "--overwrite"] + sys.argv[4:]
    run, _, _, samples = run_sampled(command, resident_mib, 0.05, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.PIPE)
    error = run.stderr.read().decode()
    if run.returncode != 0 or not samples:
        print(error.strip())
        return 1
    with open(os.path.join(out, "run.json")) as f:
        report = json.load(f)
    pixels = report["counts"]["vertices"]
    print("stage_memory: %s, %d vertices, %d cores" % (os.path.basename(dem), pixels, os.cpu_count()))
    print("%-9s %8s %10s %10s %8s" % ("stage", "seconds", "peak MiB", "end MiB", "B/pixel"))
    for name, begin, end in stage_spans(report["timings_seconds"], samples[0][0]):
        inside = [mib for t, mib in samples if begin <= t < end] or [samples[-1][1]]
        print("%-9s %8.1f %10.0f %10.0f %8.0f" % (name, end - begin, max(inside), inside[-1],
                                                 max(inside) * 2**20 / pixels))
    peak = max(mib for _, mib in samples)
    print("%-9s %8.1f %10.0f %10s %8.0f" % ("all", report["timings_seconds"]["total"], peak, "",
                                           peak * 2**20 / pixels))
    return 0


if __name__ == "__main__":
    sys.exit(main())
