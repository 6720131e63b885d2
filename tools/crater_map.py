#!/usr/bin/python3
"""The craters of a segmentation on a map: the rim circles of OUT/craters.geojson over the
hillshade of a global lon/lat DEM starting at 0 E, coloured by confidence (yellow: more
confident). The picture of docs/craters.md is made with it.

  crater_map.py DEM SEGMENT_DIR OUT.png|OUT.jpg
"""
import sys

import geopandas
import matplotlib
import numpy as np
from osgeo import gdal

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def hillshade(z):
    gy, gx = np.gradient(z)
    return np.clip(0.5 + (gx - gy) / (np.nanstd(gx) * 6), 0, 1)


def main():
    dem, out, image = sys.argv[1:4]
    ds = gdal.Open(dem)
    z = ds.GetRasterBand(1).ReadAsArray().astype(float)
    layer = geopandas.read_file(out + "/craters.geojson")
    rims = layer[layer["kind"] == "rim"]
    fig, ax = plt.subplots(figsize=(16, 8.5))
    ax.imshow(hillshade(z), cmap="gray", extent=(0, 360, -90, 90))
    for ring, confidence in zip(rims.geometry, rims["confidence"]):
        x, y = np.array(ring.exterior.coords).T
        x = np.mod(x, 360)
        if x.max() - x.min() > 180:  # (a ring across the seam: left out of the picture)
            continue
        ax.plot(x, y, color=plt.cm.autumn(confidence), lw=0.8)
    ax.set_xlim(0, 360)
    ax.set_ylim(-90, 90)
    ax.set_title(f"{len(rims)} craters read from the regions (rim circles; yellow: more "
                 "confident)")
    ax.set_xlabel("longitude (E)")
    ax.set_ylabel("latitude")
    options = {"quality": 80} if image.endswith(".jpg") else {}
    fig.savefig(image, dpi=60, bbox_inches="tight", pil_kwargs=options)


if __name__ == "__main__":
    main()
