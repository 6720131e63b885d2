#!/usr/bin/python3
"""Crater-table benchmark: the synthetic tiles and global grid of bench_craters.py (craters
known), segmented by `terrain segment` with no options, their craters.csv scored per diameter
bin by crater_table_score.py (recall, precision, median diameter and centre errors).

  bench_crater_table.py BUILD_DIR [--tiles 3] [--tile-size 1024] [--global-width 2048]
                        [--work DIR] [--args "SEGMENT OPTIONS"]

Prints one line per input and bin, the totals over the inputs and the wall time of each run;
exits 0.
"""
import argparse
import csv
import math
import os
import shlex
import subprocess
import sys
import tempfile
import time

import numpy as np
from osgeo import gdal

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_craters  # noqa: E402
import crater_table_score  # noqa: E402

gdal.UseExceptions()
VESTA_RADIUS = 255000.0  # make_global_dem.py's sphere


def read_table(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    keep = ("col", "row", "diameter_m", "depth_m", "confidence")
    return {k: np.array([float(r[k]) for r in rows]) for k in keep} if rows else {}


def pixel_metres(dem, wrap):
    """The ground length of a row of the grid: a meridian's pixel on the global grid."""
    ds = gdal.Open(dem)
    if wrap:
        return math.pi * VESTA_RADIUS / ds.RasterYSize
    return abs(ds.GetGeoTransform()[5])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    bench_craters.input_arguments(parser)
    a = parser.parse_args()
    terrain = os.path.join(a.build, "tools", "terrain")
    if not os.access(terrain, os.X_OK):
        parser.error(f"no terrain program in {a.build}/tools")
    work = a.work or tempfile.mkdtemp(prefix="bench_crater_table_")
    os.makedirs(work, exist_ok=True)
    cases = bench_craters.inputs(terrain, work, a.tiles, a.tile_size, a.global_width)
    print(f"bench_crater_table: {os.cpu_count()} cores, inputs in {work}")
    print(f"terrain segment {a.args or '(no options)'}")
    print(f"{'input':32s} {'bin px':>8s} {'recall':>14s} {'precision':>14s} {'craters':>8s} {'s':>6s}")
    total, errors = {}, {"diameter_error": [], "centre_error": [], "depth_error": []}
    for name, dem, truth_csv, wrap in cases:
        out = os.path.join(work, "out_" + os.path.splitext(os.path.basename(dem))[0])
        t0 = time.perf_counter()
        subprocess.run([terrain, "segment", dem, "-o", out, "--overwrite", "-q"] +
                       shlex.split(a.args), check=True, stdout=subprocess.DEVNULL)
        seconds = time.perf_counter() - t0
        table = read_table(os.path.join(out, "craters.csv"))
        truth = bench_craters.read_craters(truth_csv)
        ds = gdal.Open(dem)
        s = crater_table_score.score(table, truth, ds.RasterXSize, ds.RasterYSize,
                                     pixel_metres(dem, wrap), wrap)
        for k in errors:
            errors[k] += s[k + "s"]
        for i, ((lo, hi), c) in enumerate(s["bins"].items()):
            t = total.setdefault((lo, hi), [0, 0, 0, 0])
            for j in range(4):
                t[j] += c[j]
            print(f"{name if i == 0 else '':32s} {f'{lo}-{hi}':>8s} "
                  f"{bench_craters._ratio(c[0], c[1]):>14s} {bench_craters._ratio(c[2], c[3]):>14s}"
                  f" {len(table.get('col', [])) if i == 0 else '':>8} "
                  f"{f'{seconds:.1f}' if i == 0 else '':>6s}")
    for i, ((lo, hi), t) in enumerate(total.items()):
        print(f"{'all inputs' if i == 0 else '':32s} {f'{lo}-{hi}':>8s} "
              f"{bench_craters._ratio(t[0], t[1]):>14s} {bench_craters._ratio(t[2], t[3]):>14s}")
    found = sum(t[0] for t in total.values())
    scored = sum(t[1] for t in total.values())
    matched = sum(t[2] for t in total.values())
    listed = sum(t[3] for t in total.values())
    print(f"{'':32s} {'>= 10':>8s} {bench_craters._ratio(found, scored):>14s} "
          f"{bench_craters._ratio(matched, listed):>14s}")
    print(f"median diameter error {np.median(errors['diameter_error']):.3f} (relative), "
          f"median centre error {np.median(errors['centre_error']):.3f} R, "
          f"over {len(errors['diameter_error'])} matches")
    if errors["depth_error"]:
        print(f"median depth error {np.median(errors['depth_error']):.3f} (relative), over "
              f"{len(errors['depth_error'])} matches on the tiles (the global grid's generator "
              "writes no depth)")


if __name__ == "__main__":
    main()
