"""How well a crater table (craters.csv of `terrain segment`) matches the generator's craters:
the rule of the crater-table benchmark (docs/craters.md, "Scoring"), shared by
bench_crater_table.py and the tests.

A scored crater (crater_score.scored: fresh enough, wholly in the grid, not overprinted) is
*found* when a crater of the table has its centre within 0.5 R of the crater's and a diameter
within a factor 1.5 of its diameter; the closest such (by centre) is its match. Precision:
among the table's craters whose diameter in pixels falls in a bin and whose rim lies in the
grid, the share that match a generated crater (degradation <= 0.9, any size) by the same rule.
Errors over the matches: the median relative diameter error |D - D0| / D0, the median
centre error in radii |c - c0| / R0 and, where the generator gives depths (terrain synth's
depth_m, rim crest to floor as made), the median relative depth error. Distances are on the ground: a column counts col_scale
(cos latitude on a global grid) of a row.
"""
import numpy as np

from crater_score import BINS, scored, _wrap


def _close(table, truth, i, width, wrap, diameter_px):
    """Indices of the table's craters that match generated crater i, nearest first."""
    sx = truth["col_scale"][i] if "col_scale" in truth else 1.0
    r0 = truth["diameter_px"][i] / 2
    dx = _wrap(table["col"] - truth["col"][i], width, wrap) * sx
    dy = table["row"] - truth["row"][i]
    dist = np.hypot(dx, dy)
    ratio = diameter_px / truth["diameter_px"][i]
    ok = np.nonzero((dist < 0.5 * r0) & (ratio < 1.5) & (ratio > 1 / 1.5))[0]
    return ok[np.argsort(dist[ok], kind="stable")], dist / r0


def score(table, truth, width, height, pixel_m, wrap=False):
    """Per bin: (found, scored, matched, in table); and the median errors. `pixel_m`: the
    ground length of a row (the generator's diameter_px is along a meridian)."""
    n = len(table["col"]) if table else 0
    diameter_px = table["diameter_m"] / pixel_m if n else np.zeros(0)
    empty = {k: np.zeros(0) for k in ("col", "row", "diameter_m")}
    table = table if n else empty
    out = {"bins": {}, "diameter_error": [], "centre_error": [], "depth_error": []}
    keep = scored(truth, width, height, wrap)
    for lo, hi in BINS:
        found = total = 0
        for i in keep:
            if not lo <= truth["diameter_px"][i] < hi:
                continue
            total += 1
            match, dist = _close(table, truth, i, width, wrap, diameter_px)
            if match.size:
                found += 1
                j = match[0]
                out["diameter_error"].append(abs(diameter_px[j] / truth["diameter_px"][i] - 1))
                out["centre_error"].append(dist[j])
                if "depth_m" in truth and "depth_m" in table and truth["depth_m"][i] > 0:
                    out["depth_error"].append(abs(table["depth_m"][j] / truth["depth_m"][i] - 1))
        out["bins"][(lo, hi)] = [found, total, 0, 0]
    # Precision over the table.
    fresh = np.nonzero(truth["degradation"] <= 0.9)[0]
    for j in range(n):
        d = diameter_px[j]
        r = d / 2
        if table["row"][j] - r < 0 or table["row"][j] + r > height:
            continue
        if not wrap and (table["col"][j] - r < 0 or table["col"][j] + r > width):
            continue
        for (lo, hi), counts in out["bins"].items():
            if not lo <= d < hi:
                continue
            counts[3] += 1
            for i in fresh:
                match, _ = _close({k: table[k][j:j + 1] for k in ("col", "row")}, truth, i,
                                  width, wrap, diameter_px[j:j + 1])
                if match.size:
                    counts[2] += 1
                    break
    for k in ("diameter_error", "centre_error", "depth_error"):
        out[k + "s"] = out[k]
        out[k] = float(np.median(out[k])) if out[k] else float("nan")
    return out
