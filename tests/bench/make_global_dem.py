#!/usr/bin/env python3
"""Writes a global equirectangular DEM on Vesta's sphere (radius 255 km) as a tiled GeoTIFF:
craters (power-law radii, uniform on the sphere), long waves and pixel noise; radii stored as
Float32 in 2 m steps like the HAMO DNs.
  make_global_dem.py OUT.tif WIDTH [SEED] [--craters CSV]     (height = WIDTH / 2)
--craters writes the craters (the truth bench_craters.py scores against): id, lon, lat
(degrees), col, row (pixels, (0,0) the grid's top-left corner), diameter_m, diameter_px
(along a meridian), col_scale (cos lat: ground per column over ground per row), degradation
(0: every crater is fresh here)."""
import sys
import numpy as np
from osgeo import gdal, osr

R = 255000.0


def write_craters(path, lon_c, lat_c, radii, width, height):
    px = 2 * np.pi * R / width
    with open(path, "w") as f:
        f.write("id,lon,lat,col,row,diameter_m,diameter_px,col_scale,degradation\n")
        for i in range(len(radii)):
            col = lon_c[i] / (2 * np.pi) * width
            row = (np.pi / 2 - lat_c[i]) / np.pi * height
            f.write(f"{i + 1},{np.degrees(lon_c[i]):.6f},{np.degrees(lat_c[i]):.6f},{col:.4f},"
                    f"{row:.4f},{2 * radii[i]:.3f},{2 * radii[i] / px:.4f},"
                    f"{np.cos(lat_c[i]):.6f},0\n")


def usage_error(message):
    sys.exit(f"make_global_dem.py: {message} (usage: make_global_dem.py OUT.tif WIDTH [SEED] "
             "[--craters CSV])")


def main():
    args = sys.argv[1:]
    if "-h" in args or "--help" in args:
        print(__doc__)
        return
    craters = None
    if "--craters" in args:
        k = args.index("--craters")
        if k + 1 >= len(args):
            usage_error("--craters needs a file name")
        craters = args[k + 1]
        del args[k:k + 2]
    if len(args) not in (2, 3) or any(a.startswith("-") for a in args):
        usage_error("give OUT.tif and WIDTH, and optionally SEED")
    out = args[0]
    try:
        width = int(args[1])
        seed = int(args[2]) if len(args) > 2 else 7
    except ValueError:
        usage_error("WIDTH and SEED are integers")
    if width < 4 or width % 2:
        usage_error("WIDTH is an even number of pixels, 4 or more")
    height = width // 2
    rng = np.random.default_rng(seed)
    # Craters: power-law radii (metres), uniform on the sphere.
    n = max(200, width * height // 4000)
    rmin = max(2.5 * 2 * np.pi * R / width, 300.0)
    u = rng.random(n)
    radii = rmin * (1 - u) ** (-1 / 1.8)
    radii = np.minimum(radii, 60000.0)
    lon_c = rng.random(n) * 2 * np.pi
    lat_c = np.arcsin(rng.random(n) * 2 - 1)
    depth = 0.2 * radii
    if craters:
        write_craters(craters, lon_c, lat_c, radii, width, height)
    # Low-frequency relief: a few spherical harmonics-like waves.
    waves = [(rng.integers(1, 12), rng.integers(1, 8), rng.random() * 2 * np.pi, 3000.0 / (k + 1))
             for k in range(12)]
    drv = gdal.GetDriverByName("GTiff")
    ds = drv.Create(out, width, height, 1, gdal.GDT_Float32,
                    ["TILED=YES", "COMPRESS=DEFLATE", "PREDICTOR=3", "BIGTIFF=IF_SAFER", "NUM_THREADS=2"])
    srs = osr.SpatialReference()
    srs.ImportFromWkt('GEOGCS["GCS_VESTA",DATUM["D_VESTA",SPHEROID["VESTA",255000,0]],'
                      'PRIMEM["Reference_Meridian",0],UNIT["degree",0.0174532925199433]]')
    ds.SetProjection(srs.ExportToWkt())
    ds.SetGeoTransform([0.0, 360.0 / width, 0, 90.0, 0, -180.0 / height])
    band = ds.GetRasterBand(1)
    lon = (np.arange(width) + 0.5) * 2 * np.pi / width
    block = 256
    order = np.argsort(lat_c)
    ang = radii * 2.5 / R  # angular reach of each crater's profile
    for r0 in range(0, height, block):
        r1 = min(height, r0 + block)
        lat = np.pi / 2 - (np.arange(r0, r1) + 0.5) * np.pi / height
        LAT = lat[:, None]
        z = np.zeros((r1 - r0, width), np.float64)
        for (m, k, ph, amp) in waves:
            z += amp * np.cos(LAT * k) * np.sin(lon[None, :] * m + ph)
        lat_lo, lat_hi = lat[-1], lat[0]
        sel = np.nonzero((lat_c + ang >= lat_lo) & (lat_c - ang <= lat_hi))[0]
        sinl, cosl = np.sin(LAT), np.cos(LAT)
        for i in sel:
            # columns within reach (all columns near the poles)
            cl = np.cos(lat_c[i])
            reach = ang[i] / max(np.cos(min(np.pi / 2 - 1e-6, max(abs(lat_lo), abs(lat_hi)) )), 1e-6)
            if reach >= np.pi:
                cols = np.arange(width)
            else:
                c0 = int((lon_c[i] - reach) / (2 * np.pi) * width) - 1
                c1 = int((lon_c[i] + reach) / (2 * np.pi) * width) + 2
                cols = np.arange(c0, c1) % width
            dl = lon[cols][None, :] - lon_c[i]
            cosd = sinl * np.sin(lat_c[i]) + cosl * cl * np.cos(dl)
            d = np.arccos(np.clip(cosd, -1, 1)) * R / radii[i]  # distance in crater radii
            prof = np.where(d < 1, depth[i] * (d * d - 1) + 0.04 * radii[i],
                            np.where(d < 2.5, 0.04 * radii[i] * np.exp(-6 * (d - 1)), 0.0))
            z[:, cols] += prof
        z += rng.normal(0, 4.0, z.shape)
        radius = R + 2.0 * np.round(z / 2.0)
        band.WriteArray(radius.astype(np.float32), 0, r0)
        print(f"{r1}/{height}", end="\r", file=sys.stderr)
    band.SetNoDataValue(-3.4028234663852886e38)
    ds.FlushCache()
    ds = None
    print(file=sys.stderr)


if __name__ == "__main__":
    main()
