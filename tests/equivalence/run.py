#!/usr/bin/python3
"""The equivalence harness: runs the built `terrain` program's segment (the defaults and the
paper's single scale), reeb, mesh and sweep on every bundled sample DEM and compares the
SHA-256 of every file they write with the sums committed in reference.sha256 beside this
script (one `sha256  case/file` line each). run.json and graph.json are hashed without the
fields that hold timings, the input's path and the machine's state (VOLATILE below).

    tests/equivalence/run.py --terrain build/tools/terrain            # compare; exit 1 on a change
    tests/equivalence/run.py --terrain build/tools/terrain --update   # rewrite the sums
    tests/equivalence/run.py --terrain build/tools/terrain --cpus 0   # on one core (one thread)

A change in outputs made on purpose is recorded with --update, and the commit says so
(docs/development.md, "Equivalence"). CTest runs it with the label `equivalence`.
"""
import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
REFERENCE = HERE / "reference.sha256"

# Every DEM bundled with the repository (examples/data, tests/data), whole.
SAMPLES = {
    "vesta_hamo_tile": "examples/data/vesta_hamo_tile.lbl",
    "moon_ldem4_copernicus": "examples/data/moon_ldem4_copernicus.tif",
    "moon_ldem1_global": "examples/data/moon_ldem1_global.tif",
    "mars_hirise_crop": "examples/data/mars_hirise_crop.tif",
    "moon_lola_ldem4": "tests/data/moon_lola_ldem4/LDEM_4.LBL",
    "bigtujunga_srtm30m": "tests/data/earth/bigtujunga_srtm30m_utm11.tif",
}

PAPER = ["--persistence", "10", "--area-ratio", "0.5", "--cost", "graph", "--saddle-penalty", "20"]

# The jobs run on each sample: name -> (arguments after the DEM, output kind). A directory
# output is written as the case's directory; a file output as the file named.
JOBS = {
    "segment": (["-o", "{dir}"], "dir"),
    "segment_paper": (["-o", "{dir}"] + PAPER, "dir"),
    "reeb": (["--persistence", "10", "--area-ratio", "0.5", "-o", "{dir}/graph.json",
              "--write-field", "{dir}/field.tif"], "files"),
    "mesh": (["-o", "{dir}/mesh.ply"], "files"),
    "sweep": (["-o", "{dir}"], "dir"),
}
COMMAND = {"segment_paper": "segment"}

# The JSON files that record how they were made (run.json, and the Reeb graph's graph.json),
# and their fields that are not the run's results: timings, the input's path (the clone's
# location), the pages the process had, the libraries' versions. The rest is hashed, its
# keys sorted.
RECORDS = {"run.json", "graph.json"}
VOLATILE = {"timings_seconds", "seconds", "input", "pages", "versions"}


def without_volatile(value):
    if isinstance(value, dict):
        return {k: without_volatile(v) for k, v in value.items() if k not in VOLATILE}
    if isinstance(value, list):
        return [without_volatile(v) for v in value]
    return value


def sha256(path):
    h = hashlib.sha256()
    if path.name in RECORDS:
        run = without_volatile(json.loads(path.read_text()))
        h.update(json.dumps(run, sort_keys=True, separators=(",", ":")).encode())
        return h.hexdigest()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def run_case(terrain, cpus, sample, job, work):
    """Runs one job on one sample; returns {"case/file": sha256}."""
    case = f"{sample}.{job}"
    out = work / case
    if out.exists():
        shutil.rmtree(out)
    args, kind = JOBS[job]
    if kind == "files":
        out.mkdir(parents=True)
    command = [str(terrain), COMMAND.get(job, job), str(ROOT / SAMPLES[sample]), "-q"]
    command += [a.format(dir=out) for a in args]
    if cpus is not None:
        command = ["taskset", "-c", cpus] + command
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{case}: exit status {done.returncode}: {' '.join(command)}\n"
                           f"{done.stderr.strip()}")
    sums = {}
    for path in sorted(out.rglob("*")):
        if path.is_file():
            sums[f"{case}/{path.relative_to(out).as_posix()}"] = sha256(path)
    if not sums:
        raise RuntimeError(f"{case}: no output file")
    return sums


def read_reference(path):
    sums = {}
    if path.exists():
        for line in path.read_text().splitlines():
            if line.strip() and not line.startswith("#"):
                digest, name = line.split(None, 1)
                sums[name.strip()] = digest
    return sums


def write_reference(path, sums):
    lines = [f"{sums[name]}  {name}" for name in sorted(sums)]
    path.write_text("\n".join(lines) + "\n")


def differences(reference, sums):
    changed = [n for n in sorted(sums) if n in reference and reference[n] != sums[n]]
    added = [n for n in sorted(sums) if n not in reference]
    removed = [n for n in sorted(reference) if n not in sums]
    return changed, added, removed


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--terrain", default=str(ROOT / "build/tools/terrain"),
                        help="the terrain program (default: build/tools/terrain)")
    parser.add_argument("--work", default=None,
                        help="where the outputs are written (default: BUILD/equivalence; "
                             "kept for inspection, each case cleared before it runs)")
    parser.add_argument("--reference", default=str(REFERENCE), help="the sums file")
    parser.add_argument("--update", action="store_true",
                        help="rewrite the sums file from this run, printing what changed")
    parser.add_argument("--cpus", default=None,
                        help="run every job under `taskset -c CPUS` (e.g. 0: one core, so "
                             "one thread)")
    parser.add_argument("--only", default=None,
                        help="only the cases whose name contains this text (no --update)")
    options = parser.parse_args()

    terrain = Path(options.terrain).resolve()
    if not os.access(terrain, os.X_OK):
        print(f"equivalence: {terrain} is not a program; build it first "
              "(cmake --build build --target terrain_cli) or pass --terrain", file=sys.stderr)
        return 2
    if options.update and options.only:
        print("equivalence: --update rewrites every case; drop --only", file=sys.stderr)
        return 2
    build = terrain.parent.parent if terrain.parent.name == "tools" else terrain.parent
    work = Path(options.work) if options.work else build / "equivalence"
    work.mkdir(parents=True, exist_ok=True)
    reference_path = Path(options.reference)
    reference = read_reference(reference_path)

    cases = [(s, j) for s in SAMPLES for j in JOBS
             if not options.only or options.only in f"{s}.{j}"]
    sums = {}
    start = time.monotonic()
    for sample, job in cases:
        t0 = time.monotonic()
        try:
            case_sums = run_case(terrain, options.cpus, sample, job, work)
        except RuntimeError as e:
            print(f"equivalence: {e}", file=sys.stderr)
            return 1
        sums.update(case_sums)
        print(f"{sample}.{job}: {len(case_sums)} files, {time.monotonic() - t0:.1f} s",
              flush=True)
    if options.only:
        prefixes = {f"{s}.{j}/" for s, j in cases}
        reference = {n: d for n, d in reference.items()
                     if any(n.startswith(p) for p in prefixes)}

    changed, added, removed = differences(reference, sums)
    for label, names in (("changed", changed), ("new", added), ("gone", removed)):
        for name in names:
            print(f"{label}: {name}")
    total = f"{len(cases)} cases, {len(sums)} files in {time.monotonic() - start:.0f} s"
    if options.update:
        write_reference(reference_path, sums)
        print(f"equivalence: {reference_path} rewritten ({total}; {len(changed)} changed, "
              f"{len(added)} new, {len(removed)} gone)")
        return 0
    if changed or added or removed:
        print(f"equivalence: outputs differ from {reference_path} ({total}; {len(changed)} "
              f"changed, {len(added)} new, {len(removed)} gone). Outputs kept in {work}. If the "
              "change is meant, run with --update and say so in the commit.")
        return 1
    print(f"equivalence: every output identical to the reference ({total})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
