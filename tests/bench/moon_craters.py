#!/usr/bin/python3
"""A look at a segmentation of a global Moon DEM (such as LDEM_4) against 29 well-known
craters of 58-265 km between 58 S and 52 N: for each, whether the region holding most of its
inner bowl is a region of its own (crater_score.py's rule: >= 70 % of it within 1.3 R, >= 40 %
of the bowl covered) and concave (mean shape index x100 below --concave-below: 43.75 by
default, the concave landform classes; 50 for a mean shape index below 0).

  moon_craters.py SEGMENT_DIR [--concave-below 43.75]

SEGMENT_DIR is `terrain segment`'s output on a global lon/lat grid of the Moon starting at
0 E (labels.tif, regions.geojson). The positions and diameters are approximate (a few
tenths of a degree, a few km): a look, not a catalogue.
"""
import argparse
import json
import os
import sys

import numpy as np
from osgeo import gdal

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crater_score  # noqa: E402

gdal.UseExceptions()
MOON_RADIUS_KM = 1737.4
# name, latitude, longitude (east, -180..180), diameter km.
CRATERS = [
    ("Copernicus", 9.62, -20.08, 93), ("Tycho", -43.31, -11.36, 85),
    ("Clavius", -58.4, -14.4, 225), ("Ptolemaeus", -9.2, -1.8, 154),
    ("Alphonsus", -13.4, -3.2, 119), ("Arzachel", -18.2, -1.9, 96),
    ("Plato", 51.6, -9.4, 101), ("Archimedes", 29.7, -4.0, 81),
    ("Eratosthenes", 14.5, -11.3, 58), ("Theophilus", -11.4, 26.4, 99),
    ("Cyrillus", -13.2, 24.0, 98), ("Catharina", -18.1, 23.6, 99),
    ("Langrenus", -8.9, 61.0, 132), ("Petavius", -25.1, 60.4, 177),
    ("Aristoteles", 50.2, 17.4, 88), ("Gassendi", -17.6, -40.1, 110),
    ("Grimaldi", -5.2, -68.6, 173), ("Schickard", -44.3, -54.6, 206),
    ("Humboldt", -27.2, 80.9, 207), ("Tsiolkovskiy", -21.2, 128.9, 185),
    ("Daedalus", -5.9, 179.4, 93), ("Jackson", 22.4, -163.1, 71),
    ("King", 5.0, 120.5, 76), ("Aitken", -16.8, 173.4, 135),
    ("Van de Graaff", -27.0, 172.0, 233), ("Gagarin", -20.2, 149.2, 265),
    ("Fabry", 42.9, 100.7, 179), ("Landau", 41.6, -118.1, 214),
    ("Campbell", 45.3, 151.4, 219),
]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("segment_dir")
    parser.add_argument("--concave-below", type=float, default=crater_score.CONCAVE_BELOW)
    a = parser.parse_args()
    ds = gdal.Open(os.path.join(a.segment_dir, "labels.tif"))
    labels = ds.GetRasterBand(1).ReadAsArray().astype(np.int64)
    mean = np.full(int(labels.max()) + 1, np.nan)
    with open(os.path.join(a.segment_dir, "regions.geojson")) as f:
        for feature in json.load(f)["features"]:
            p = feature["properties"]
            mean[p["id"]] = np.nan if p["field_mean"] is None else p["field_mean"]
    h, w = labels.shape
    pixel_km = 2 * np.pi * MOON_RADIUS_KM / w
    craters = {
        "col": np.array([(lon % 360) / 360 * w for _, _, lon, _ in CRATERS]),
        "row": np.array([(90 - lat) / 180 * h for _, lat, _, _ in CRATERS]),
        "diameter_px": np.array([d / pixel_km for _, _, _, d in CRATERS]),
        "col_scale": np.array([np.cos(np.radians(lat)) for _, lat, _, _ in CRATERS]),
    }
    found, match = crater_score.find(labels, mean < a.concave_below, craters,
                                     np.arange(len(CRATERS)), wrap=True)
    for (name, _, _, d), ok, k in zip(CRATERS, found, match):
        print(f"{name:14s} {d:4d} km  region {k:6d}  mean {mean[k]:5.1f}  {'found' if ok else 'missed'}")
    print(f"found {int(found.sum())} of {len(CRATERS)} (concave below {a.concave_below})")


if __name__ == "__main__":
    main()
