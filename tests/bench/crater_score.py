"""How well a label map holds known craters: the rule of the crater benchmarks
(docs/landforms.md, "Scoring against known craters"), shared by bench_craters.py and the tests.

A crater is *found* when the region holding most of its inner bowl (the pixels within 0.6 R
of its centre) is concave (its mean shape index in a concave class: below 43.75 on the
x100 scale, under Koenderink's saddle band), has >= 70 % of its pixels within 1.3 R of the
centre and covers >= 40 % of the inner bowl. Distances are on the ground: a column counts
col_scale (cos latitude on a global grid) of a row.

Craters scored: degradation <= 0.5, diameter >= 10 px, wholly in the grid (1.3 R from each
edge; on a global grid |latitude| <= 60 and any longitude, the seam wrapping), and not
overprinted: no younger crater at least half as wide has its rim (1.2 R) over the centre.

Precision: among the concave regions not touching the grid's edge whose equivalent diameter
(of a disk of the same pixel area) is in a bin, the share that are craters: the region found
for a scored crater, or one whose centroid lies within 0.6 R of a generated crater
(degradation <= 0.9) at least 1/1.3 of its equivalent diameter.
"""
import numpy as np

BINS = ((10, 20), (20, 50), (50, 200))
CONCAVE_BELOW = 43.75  # the top of Koenderink's "saddle rut" class, x100


def _column(craters, name, default):
    return np.asarray(craters[name], float) if name in craters else np.full(len(craters["col"]), default)


def scored(craters, width, height, wrap=False):
    """Indices of the craters to score (see the module's docstring)."""
    col, row = _column(craters, "col", 0), _column(craters, "row", 0)
    d, q = _column(craters, "diameter_px", 0), _column(craters, "degradation", 0)
    sx = _column(craters, "col_scale", 1)
    r = d / 2
    keep = (q <= 0.5) & (d >= 10) & (row - 1.3 * r >= 0) & (row + 1.3 * r <= height)
    if wrap:
        keep &= np.abs(_column(craters, "lat", 0)) <= 60
    else:
        keep &= (col - 1.3 * r / sx >= 0) & (col + 1.3 * r / sx <= width)
    wide = np.nonzero(d >= 5)[0]
    out = []
    for i in np.nonzero(keep)[0]:
        later = wide[(wide > i) & (d[wide] >= 0.5 * d[i])]
        if later.size:
            dx = _wrap(col[later] - col[i], width, wrap) * sx[i]
            if np.any(np.hypot(dx, row[later] - row[i]) < 1.2 * r[later]):
                continue
        out.append(i)
    return np.array(out, int)


def _wrap(dx, width, wrap):
    if not wrap:
        return dx
    return (dx + width / 2) % width - width / 2


def _window(labels, c, r, reach_cols, reach_rows, wrap):
    h, w = labels.shape
    r0, r1 = max(0, int(r - reach_rows) - 1), min(h, int(r + reach_rows) + 2)
    cols = np.arange(int(c - reach_cols) - 1, int(c + reach_cols) + 2)
    cols = cols % w if wrap else cols[(cols >= 0) & (cols < w)]
    return labels[r0:r1][:, cols], np.arange(r0, r1), cols


def find(labels, concave, craters, indices, wrap=False):
    """Per scored crater: whether it is found, and the region holding most of its bowl."""
    h, w = labels.shape
    areas = np.bincount(labels.ravel())
    col, row = _column(craters, "col", 0), _column(craters, "row", 0)
    d, sx = _column(craters, "diameter_px", 0), _column(craters, "col_scale", 1)
    found = np.zeros(len(indices), bool)
    match = np.zeros(len(indices), int)
    for j, i in enumerate(indices):
        r = d[i] / 2
        window, rows, cols = _window(labels, col[i], row[i], 1.4 * r / sx[i], 1.4 * r, wrap)
        dx = _wrap(cols + 0.5 - col[i], w, wrap) * sx[i]
        dist = np.hypot(dx[None, :], rows[:, None] + 0.5 - row[i])
        bowl = window[(dist <= 0.6 * r) & (window > 0)]
        if bowl.size == 0:
            continue
        ids, counts = np.unique(bowl, return_counts=True)
        k = ids[np.argmax(counts)]
        match[j] = k
        near = np.count_nonzero((window == k) & (dist <= 1.3 * r))
        found[j] = (concave[k] and near >= 0.7 * areas[k]
                    and counts.max() >= 0.4 * np.count_nonzero(dist <= 0.6 * r))
    return found, match


def precision(labels, concave, craters, matched, wrap=False):
    """Per bin: (concave regions of that size that are craters, concave regions of that size)."""
    h, w = labels.shape
    n = int(labels.max()) + 1
    flat = labels.ravel()
    areas = np.bincount(flat, minlength=n).astype(float)
    yy, xx = np.indices(labels.shape)
    if wrap:  # centroids on the circle of longitudes
        ang = (xx.ravel() + 0.5) / w * 2 * np.pi
        cx = np.arctan2(np.bincount(flat, np.sin(ang), n), np.bincount(flat, np.cos(ang), n))
        cx = (cx % (2 * np.pi)) / (2 * np.pi) * w
    else:
        cx = np.bincount(flat, xx.ravel() + 0.5, n) / np.maximum(areas, 1)
    cy = np.bincount(flat, yy.ravel() + 0.5, n) / np.maximum(areas, 1)
    # Equivalent diameters in row pixels (a global grid's columns shrink by cos latitude).
    scale = np.cos((0.5 - cy / h) * np.pi) if wrap else np.ones(n)
    eqd = 2 * np.sqrt(areas * scale / np.pi)
    edge = np.zeros(n, bool)
    for side in ((labels[:, 0], labels[:, -1]) if not wrap else ()) + (labels[0], labels[-1]):
        edge[side] = True
    col, row = _column(craters, "col", 0), _column(craters, "row", 0)
    d, q = _column(craters, "diameter_px", 0), _column(craters, "degradation", 0)
    sx = _column(craters, "col_scale", 1)
    out = {}
    for lo, hi in BINS:
        regions = [k for k in range(1, n)
                   if concave[k] and not edge[k] and lo <= eqd[k] < hi
                   and (not wrap or abs(0.5 - cy[k] / h) * 180 <= 60)]
        good = 0
        for k in regions:
            if k in matched:
                good += 1
                continue
            dist = np.hypot(_wrap(col - cx[k], w, wrap) * sx, row - cy[k])
            if np.any((q <= 0.9) & (dist < 0.3 * d) & (d >= eqd[k] / 1.3)):
                good += 1
        out[(lo, hi)] = (good, len(regions))
    return out


def score(labels, field_mean, craters, wrap=False, concave_below=CONCAVE_BELOW):
    """Recall and precision per bin of a label map (0 = no region) whose region k has mean
    field field_mean[k] (x100 shape index), against a crater table (a dict of columns).
    concave_below: the mean field under which a region is concave (50: mean SI < 0)."""
    concave = np.asarray(field_mean, float) < concave_below
    h, w = labels.shape
    indices = scored(craters, w, h, wrap)
    found, match = find(labels, concave, craters, indices, wrap)
    prec = precision(labels, concave, craters, set(match[found].tolist()), wrap)
    d = _column(craters, "diameter_px", 0)[indices]
    rows = []
    for lo, hi in BINS:
        sel = (d >= lo) & (d < hi)
        good, total = prec[(lo, hi)]
        rows.append({"bin": f"{lo}-{hi}", "craters": int(sel.sum()),
                     "found": int(found[sel].sum()), "regions": total, "true": good})
    return rows
