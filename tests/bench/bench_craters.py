#!/usr/bin/python3
"""Crater benchmark: synthetic tiles and a synthetic global grid whose craters are known,
segmented by `terrain segment`, scored per diameter bin by crater_score.py (recall: the
generated craters that are a concave region of their own; precision: the concave
crater-sized regions that are generated craters).

  bench_craters.py BUILD_DIR [--tiles 3] [--tile-size 1024] [--global-width 2048]
                   [--work DIR] [--args "SEGMENT OPTIONS"] [--compare "SEGMENT OPTIONS"]
                   [--concave-below 43.75]

--args: the options of the run scored (default: none, the landform defaults); --compare: a
second run on the same inputs, scored beside it (for instance the paper's single scale,
"--area-ratio 0.5 --persistence 10"). Prints one table per run and the wall time of each
segmentation; exits 0.
"""
import argparse
import csv
import json
import os
import shlex
import subprocess
import sys
import tempfile
import time

import numpy as np
from osgeo import gdal

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crater_score  # noqa: E402

gdal.UseExceptions()
HERE = os.path.dirname(os.path.abspath(__file__))
CONCAVE_BELOW = crater_score.CONCAVE_BELOW


def read_craters(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]} if rows else {}


def segment(terrain, dem, out, args):
    t0 = time.perf_counter()
    subprocess.run([terrain, "segment", dem, "-o", out, "--overwrite", "-q"] + args, check=True,
                   stdout=subprocess.DEVNULL)
    seconds = time.perf_counter() - t0
    ds = gdal.Open(os.path.join(out, "labels.tif"))
    labels = ds.GetRasterBand(1).ReadAsArray().astype(np.int64)
    with open(os.path.join(out, "regions.geojson")) as f:
        features = json.load(f)["features"]
    mean = np.full(int(labels.max()) + 1, np.nan)
    for feature in features:
        p = feature["properties"]
        mean[p["id"]] = p["field_mean"] if p["field_mean"] is not None else np.nan
    return labels, mean, seconds


def inputs(terrain, work, tiles, size, global_width):
    out = []
    for k in range(tiles):
        lbl, craters = os.path.join(work, f"tile{k}.lbl"), os.path.join(work, f"tile{k}.csv")
        if not os.path.exists(craters):
            subprocess.run([terrain, "synth", "-o", lbl, "--width", str(size), "--height",
                            str(size), "--seed", str(101 + k), "--lat", str(-30 + 25 * k),
                            "--craters", craters, "--overwrite", "-q"], check=True,
                           stdout=subprocess.DEVNULL)
        out.append((f"tile {k} ({size} px, seed {101 + k})", lbl, craters, False))
    if global_width:
        tif = os.path.join(work, f"global{global_width}.tif")
        craters = os.path.join(work, f"global{global_width}.csv")
        if not os.path.exists(craters):
            subprocess.run([sys.executable, os.path.join(HERE, "make_global_dem.py"), tif,
                            str(global_width), "7", "--craters", craters], check=True,
                           stderr=subprocess.DEVNULL)
        out.append((f"global {global_width} x {global_width // 2}", tif, craters, True))
    return out


def input_arguments(parser):
    """The arguments of the crater benchmarks: the build, the inputs made and the options."""
    parser.add_argument("build")
    parser.add_argument("--tiles", type=int, default=3)
    parser.add_argument("--tile-size", type=int, default=1024)
    parser.add_argument("--global-width", type=int, default=2048)
    parser.add_argument("--work")
    parser.add_argument("--args", default="")


def run(terrain, cases, work, args, title):
    total = {}
    print(f"\n== {title}: terrain segment {' '.join(args) or '(no options)'}")
    print(f"{'input':32s} {'bin px':>8s} {'recall':>14s} {'precision':>14s} {'regions':>8s} {'s':>6s}")
    for name, dem, craters, wrap in cases:
        out = os.path.join(work, f"{title}_{os.path.splitext(os.path.basename(dem))[0]}")
        labels, mean, seconds = segment(terrain, dem, out, args)
        rows = crater_score.score(labels, mean, read_craters(craters), wrap, CONCAVE_BELOW)
        for i, r in enumerate(rows):
            t = total.setdefault(r["bin"], [0, 0, 0, 0])
            t[0] += r["found"]; t[1] += r["craters"]; t[2] += r["true"]; t[3] += r["regions"]
            print(f"{name if i == 0 else '':32s} {r['bin']:>8s} {_ratio(r['found'], r['craters']):>14s}"
                  f" {_ratio(r['true'], r['regions']):>14s} {int(labels.max()) if i == 0 else '':>8}"
                  f" {f'{seconds:.1f}' if i == 0 else '':>6s}")
    for i, (b, t) in enumerate(total.items()):
        print(f"{'all inputs' if i == 0 else '':32s} {b:>8s} {_ratio(t[0], t[1]):>14s} {_ratio(t[2], t[3]):>14s}")
    found = sum(t[0] for t in total.values())
    scored = sum(t[1] for t in total.values())
    print(f"{'':32s} {'>= 10':>8s} {_ratio(found, scored):>14s}")


def _ratio(a, b):
    return f"{a}/{b} {a / b:.2f}" if b else f"{a}/{b}  -  "


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    input_arguments(parser)
    parser.add_argument("--compare")
    parser.add_argument("--concave-below", type=float, default=crater_score.CONCAVE_BELOW,
                        help="the mean shape index x100 under which a region is concave "
                             "(default 43.75, the concave landform classes; 50: mean SI < 0)")
    a = parser.parse_args()
    global CONCAVE_BELOW
    CONCAVE_BELOW = a.concave_below
    terrain = os.path.join(a.build, "tools", "terrain")
    if not os.access(terrain, os.X_OK):
        parser.error(f"no terrain program in {a.build}/tools")
    work = a.work or tempfile.mkdtemp(prefix="bench_craters_")
    os.makedirs(work, exist_ok=True)
    cases = inputs(terrain, work, a.tiles, a.tile_size, a.global_width)
    print(f"bench_craters: {os.cpu_count()} cores, inputs in {work}")
    run(terrain, cases, work, shlex.split(a.args), "scored")
    if a.compare is not None:
        run(terrain, cases, work, shlex.split(a.compare), "compared")


if __name__ == "__main__":
    main()
