#!/usr/bin/python3
"""A look at a segmentation of a global Moon DEM (such as LDEM_4) against 29 well-known
craters of 58-265 km between 58 S and 52 N: for each, whether the region holding most of its
inner bowl is a region of its own (crater_score.py's rule: >= 70 % of it within 1.3 R, >= 40 %
of the bowl covered) and concave (mean shape index x100 below --concave-below: 43.75 by
default, the concave landform classes; 50 for a mean shape index below 0).

  moon_craters.py SEGMENT_DIR [--concave-below 43.75] [--catalogue CSV]

SEGMENT_DIR is `terrain segment`'s output on a global grid of the Moon, geographic or
equirectangular, whose left edge may be at any longitude (read from labels.tif's
geotransform and CRS; labels.tif, regions.geojson, craters.csv). The positions and diameters are approximate
(a few tenths of a degree, a few km): a look, not a catalogue.

With --catalogue CSV (columns lon, lat, diameter_km; east-positive longitudes), the craters
of that catalogue between --min-km and --max-km and within --max-lat of the equator are
scored instead, per diameter bin: the regions by the rule above (with why each miss is
missed: the bowl's region not concave, spread beyond 1.3 R, or covering under 40 % of the
bowl), the share of the concave regions of that size whose centroid lies within 0.6 R of a
catalogued crater, and the crater table (craters.csv) by crater_table_score.py's rule (a
table crater within 0.5 R of the centre with a diameter within a factor 1.5): its recall, and
its precision against the catalogue's craters of the same range and against all of them. No
catalogue ships with the project: a published one is the user's to give.
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
    parser.add_argument("--catalogue", help="CSV of lon, lat, diameter_km to score against")
    parser.add_argument("--min-km", type=float, default=60)
    parser.add_argument("--max-km", type=float, default=300)
    parser.add_argument("--max-lat", type=float, default=60)
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
    origin = grid_origin(ds)
    if a.catalogue:
        score_catalogue(a, labels, mean, pixel_km, origin)
        return
    col, row = grid_position([c[2] for c in CRATERS], [c[1] for c in CRATERS], origin, w, h)
    craters = {
        "col": col,
        "row": row,
        "diameter_px": np.array([d / pixel_km for _, _, _, d in CRATERS]),
        "col_scale": np.array([np.cos(np.radians(lat)) for _, lat, _, _ in CRATERS]),
    }
    found, match = crater_score.find(labels, mean < a.concave_below, craters,
                                     np.arange(len(CRATERS)), wrap=True)
    for (name, _, _, d), ok, k in zip(CRATERS, found, match):
        print(f"{name:14s} {d:4d} km  region {k:6d}  mean {mean[k]:5.1f}  {'found' if ok else 'missed'}")
    print(f"found {int(found.sum())} of {len(CRATERS)} (concave below {a.concave_below})")


def grid_origin(ds):
    """The longitude of a global grid's left edge and the latitude of its top edge (degrees),
    from its geotransform and CRS (a geographic or an equirectangular one); 0 and 90 without
    a CRS."""
    from osgeo import osr
    wkt = ds.GetProjection()
    t = ds.GetGeoTransform()
    if not wkt:
        return 0.0, 90.0
    srs = osr.SpatialReference()
    srs.ImportFromWkt(wkt)
    srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    if srs.IsGeographic():
        return t[0], t[3]
    geographic = srs.CloneGeogCS()
    geographic.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    to_lonlat = osr.CoordinateTransformation(srs, geographic)
    w, h = ds.RasterXSize, ds.RasterYSize
    lon, _, _ = to_lonlat.TransformPoint(t[0], t[3] + 0.5 * h * t[5])
    _, lat, _ = to_lonlat.TransformPoint(t[0] + 0.5 * w * t[1], t[3])
    return lon, lat


def grid_position(lon, lat, origin, w, h):
    """Column and row (fractional) of lon/lat on a global grid of w x h pixels whose left and
    top edges are at origin = (longitude, latitude)."""
    col = ((np.asarray(lon, float) - origin[0]) % 360) / 360 * w
    row = (origin[1] - np.asarray(lat, float)) / 180 * h
    return col, row


def read_catalogue(path, min_km, max_km, max_lat):
    import csv
    with open(path, newline="") as f:
        rows = [(float(r["lon"]), float(r["lat"]), float(r["diameter_km"]))
                for r in csv.DictReader(f)]
    rows = [r for r in rows if min_km <= r[2] <= max_km and abs(r[1]) <= max_lat]
    lon, lat, d = (np.array(c, float) for c in zip(*rows)) if rows else (np.zeros(0),) * 3
    return lon, lat, d


def score_catalogue(a, labels, mean, pixel_km, origin):
    h, w = labels.shape
    lon, lat, d = read_catalogue(a.catalogue, a.min_km, a.max_km, a.max_lat)
    col, row = grid_position(lon, lat, origin, w, h)
    craters = {"col": col, "row": row,
               "diameter_px": d / pixel_km, "col_scale": np.cos(np.radians(lat))}
    everything = np.arange(len(d))
    concave = mean < a.concave_below
    found, match = crater_score.find(labels, concave, craters, everything, wrap=True)
    # Why each miss is missed (the rule's three tests, on the region found for it).
    areas = np.bincount(labels.ravel())
    why = {"not concave": 0, "spreads beyond 1.3 R": 0, "under 40 % of the bowl": 0}
    for i in np.nonzero(~found)[0]:
        k = match[i]
        if not concave[k]:
            why["not concave"] += 1
            continue
        r = craters["diameter_px"][i] / 2
        sx = craters["col_scale"][i]
        window, rows, cols = crater_score._window(labels, craters["col"][i], craters["row"][i],
                                                  1.4 * r / sx, 1.4 * r, True)
        dx = crater_score._wrap(cols + 0.5 - craters["col"][i], w, True) * sx
        dist = np.hypot(dx[None, :], rows[:, None] + 0.5 - craters["row"][i])
        if np.count_nonzero((window == k) & (dist <= 1.3 * r)) < 0.7 * areas[k]:
            why["spreads beyond 1.3 R"] += 1
        else:
            why["under 40 % of the bowl"] += 1
    bins = ((60, 100), (100, 150), (150, 300))
    print(f"{len(d)} catalogued craters {a.min_km:g}-{a.max_km:g} km, |lat| <= {a.max_lat:g}")
    for lo, hi in bins:
        sel = (d >= lo) & (d < hi) if hi < a.max_km else (d >= lo) & (d <= hi)
        print(f"  regions {lo:3d}-{hi:3d} km: {int(found[sel].sum())} of {int(sel.sum())}")
    print(f"regions: {int(found.sum())} of {len(d)} = {found.mean() if len(d) else 0:.3f}"
          f" ({', '.join(f'{v} {k}' for k, v in why.items())})")
    # Concave regions of crater size that are catalogued craters (centroid within 0.6 R).
    bins_px = tuple((lo / pixel_km, hi / pixel_km) for lo, hi in ((a.min_km, a.max_km),))
    saved = crater_score.BINS
    crater_score.BINS = bins_px
    try:
        good = crater_score.precision(labels, concave, dict(craters, degradation=np.zeros(len(d))),
                                      set(match[found].tolist()), wrap=True)
    finally:
        crater_score.BINS = saved
    g, n = next(iter(good.values()))
    print(f"concave regions {a.min_km:g}-{a.max_km:g} km that are catalogued craters: "
          f"{g} of {n} = {g / max(n, 1):.3f}")
    table_path = os.path.join(a.segment_dir, "craters.csv")
    if not os.path.exists(table_path):
        return
    import csv
    with open(table_path, newline="") as f:
        rows = list(csv.DictReader(f))
    t_lon = np.array([float(r["lon"]) for r in rows])
    t_lat = np.array([float(r["lat"]) for r in rows])
    t_d = np.array([float(r["diameter_m"]) for r in rows]) / 1000
    t_col, t_row = grid_position(t_lon, t_lat, origin, w, h)
    table = {"col": t_col, "row": t_row}
    hit = np.zeros(len(d), bool)
    for i in range(len(d)):
        sx = craters["col_scale"][i]
        dist = np.hypot(crater_score._wrap(table["col"] - craters["col"][i], w, True) * sx,
                        table["row"] - craters["row"][i])
        ratio = t_d / d[i]
        hit[i] = np.any((dist < 0.25 * craters["diameter_px"][i]) & (ratio < 1.5) & (ratio > 1 / 1.5))
    in_range = (t_d >= a.min_km) & (t_d <= a.max_km) & (np.abs(t_lat) <= a.max_lat)
    # Precision against the craters of the same range, and against the whole catalogue (any
    # size, any latitude): a listed crater of 60 km may be a catalogued one of 55.
    a_lon, a_lat, a_d = read_catalogue(a.catalogue, 0, np.inf, 90)
    a_col, a_row = grid_position(a_lon, a_lat, origin, w, h)
    every = {"col": a_col, "row": a_row, "diameter_px": a_d / pixel_km,
             "col_scale": np.cos(np.radians(a_lat))}
    true = {"range": 0, "any": 0}
    for j in np.nonzero(in_range)[0]:
        for key, (c, km) in (("range", (craters, d)), ("any", (every, a_d))):
            dist = np.hypot(crater_score._wrap(c["col"] - table["col"][j], w, True) * c["col_scale"],
                            c["row"] - table["row"][j])
            ratio = t_d[j] / km
            true[key] += bool(np.any((dist < 0.25 * c["diameter_px"]) & (ratio < 1.5)
                                     & (ratio > 1 / 1.5)))
    n = max(int(in_range.sum()), 1)
    print(f"crater table: recall {int(hit.sum())} of {len(d)} = {hit.mean() if len(d) else 0:.3f};"
          f" precision {true['range']} of {int(in_range.sum())} = {true['range'] / n:.3f} against"
          f" the catalogue's {a.min_km:g}-{a.max_km:g} km, {true['any']} = {true['any'] / n:.3f}"
          " against all of it")

if __name__ == "__main__":
    main()
