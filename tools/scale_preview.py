#!/usr/bin/python3
"""The chosen analysis scale as a picture: the radius raster that `terrain field --radius auto`
writes (<stem>_radius.tif), in colours by octave over the hillshade of the DEM, with the
region boundaries of a segmentation's labels.tif on top and a legend in kilometres.

  scale_preview.py DEM RADIUS.tif LABELS.tif OUT.png [--title TEXT]

The pictures of docs/segment.md ("Landforms at their own scale") are made with it.
"""
import argparse

import numpy as np
from osgeo import gdal

gdal.UseExceptions()


def read(path):
    ds = gdal.Open(path)
    band = ds.GetRasterBand(1)
    values = band.ReadAsArray().astype(np.float64)
    nodata = band.GetNoDataValue()
    if nodata is not None:
        values[values == nodata] = np.nan
    values = values * (band.GetScale() or 1) + (band.GetOffset() or 0)
    return values, ds.GetGeoTransform()


def hillshade(z, transform):
    gy, gx = np.gradient(np.nan_to_num(z, nan=np.nanmean(z)), abs(transform[5]), abs(transform[1]))
    slope = np.arctan(np.hypot(gx, gy))
    aspect = np.arctan2(-gx, gy)
    az, alt = np.radians(315), np.radians(45)
    shade = np.sin(alt) * np.cos(slope) + np.cos(alt) * np.sin(slope) * np.cos(az - aspect)
    return np.clip(shade, 0, 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dem")
    parser.add_argument("radius")
    parser.add_argument("labels")
    parser.add_argument("out")
    parser.add_argument("--title", default="")
    a = parser.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import colors

    dem, transform = read(a.dem)
    radius, _ = read(a.radius)
    labels, _ = read(a.labels)
    rungs = np.unique(radius[np.isfinite(radius)])
    index = np.searchsorted(rungs, radius)
    index[~np.isfinite(radius)] = 0
    cmap = plt.get_cmap("viridis", len(rungs))
    rgb = cmap(index / max(1, len(rungs) - 1))[..., :3]
    # A global grid's hillshade is flattened by its metres per degree: shade in pixels.
    shade = hillshade(dem, (0, 1, 0, 0, 0, -1) if abs(transform[1]) < 1 else transform)
    image = rgb * (0.45 + 0.55 * shade[..., None])
    edge = np.zeros(labels.shape, bool)
    edge[:, 1:] |= labels[:, 1:] != labels[:, :-1]
    edge[1:, :] |= labels[1:, :] != labels[:-1, :]
    image[edge] = 0
    image[~np.isfinite(radius)] = 1
    h, w = labels.shape
    fig_w = 10.0
    fig, ax = plt.subplots(figsize=(fig_w, fig_w * h / w * 0.92 + 0.8), dpi=110)
    ax.imshow(image, interpolation="nearest")
    ax.set_axis_off()
    if a.title:
        ax.set_title(a.title, fontsize=10)
    handles = [plt.Rectangle((0, 0), 1, 1, color=cmap(k / max(1, len(rungs) - 1)))
               for k in range(len(rungs))]
    share = [np.count_nonzero(index[np.isfinite(radius)] == k) / np.count_nonzero(np.isfinite(radius))
             for k in range(len(rungs))]
    names = [f"{r / 1000:.3g} km ({s:.0%})" for r, s in zip(rungs, share)]
    ax.legend(handles, names, title="radius chosen", loc="upper left",
              bbox_to_anchor=(1.01, 1), fontsize=8, title_fontsize=8, frameon=False)
    fig.savefig(a.out, bbox_inches="tight")
    print(f"{a.out}: {len(rungs)} radii, {int(np.nanmax(labels))} regions")


if __name__ == "__main__":
    main()
