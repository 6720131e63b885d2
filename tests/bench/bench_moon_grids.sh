#!/usr/bin/env bash
# Benchmark: the real Moon at several pixel sizes against a published crater catalogue. From
# LDEM_4 (PDS3, radii; or any global Moon DEM) it makes heights and the grids docs/landforms.md
# quotes: LDEM_4 itself (1440 x 720, 7.6 km pixels), averaged to 1024 x 512 (10.7 km, the
# geographic IAU_2015:30100 CRS, left edge at 180 W) and resampled by cubic spline to
# 2880 x 1440 (3.8 km); segments each with no options (plus ARGS) and scores it with
# moon_craters.py --catalogue (regions found per diameter bin, why the others are missed, the
# crater table's recall and precision). No catalogue ships with the project: CATALOGUE is a
# CSV of lon, lat, diameter_km (east-positive), such as Head et al. 2010's.
#   tests/bench/bench_moon_grids.sh BUILD LDEM_4.LBL CATALOGUE [ARGS...]
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: bench_moon_grids.sh BUILD LDEM_4.LBL CATALOGUE [segment options]" >&2
  exit 2
fi
build="$1" ldem="$2" catalogue="$3"
shift 3
terrain="$build/tools/terrain"
here="$(cd "$(dirname "$0")" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# Heights (radius - 1737.4 km: the DEM's scale, without its offset) as Float32 on its grid.
/usr/bin/python3 - "$ldem" "$work/heights.tif" <<'EOF'
import sys
import numpy as np
from osgeo import gdal
gdal.UseExceptions()
src = gdal.Open(sys.argv[1])
band = src.GetRasterBand(1)
heights = band.ReadAsArray().astype(np.float32) * (band.GetScale() or 1.0)
out = gdal.GetDriverByName("GTiff").Create(sys.argv[2], src.RasterXSize, src.RasterYSize, 1,
                                           gdal.GDT_Float32)
out.SetGeoTransform(src.GetGeoTransform())
out.SetProjection(src.GetProjection())
out.GetRasterBand(1).WriteArray(heights)
out = None
EOF
gdalwarp -q -t_srs IAU_2015:30100 -te -180 -90 180 90 -ts 1024 512 -r average \
  "$work/heights.tif" "$work/moon_1024.tif"
gdalwarp -q -ts 2880 1440 -r cubicspline "$work/heights.tif" "$work/moon_2880.tif"

for grid in "LDEM_4:$ldem" "1024x512:$work/moon_1024.tif" "2880x1440:$work/moon_2880.tif"; do
  name="${grid%%:*}" dem="${grid#*:}"
  out="$work/out_$name"
  start=$(date +%s.%N)
  "$terrain" segment -q "$dem" -o "$out" "$@" > "$work/summary"
  seconds=$(echo "$(date +%s.%N) - $start" | bc)
  echo "== $name: $(cat "$work/summary" | sed 's/^[^:]*: //') ($(printf '%.1f' "$seconds") s)"
  /usr/bin/python3 "$here/moon_craters.py" "$out" --catalogue "$catalogue" --concave-below 50
done
