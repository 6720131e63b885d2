#!/usr/bin/env bash
# Benchmark: what the landform defaults cost. `terrain segment` with no options (the field's
# radius chosen per pixel, --min-area auto) against the paper's single scale
# (--area-ratio 0.5 --persistence 10) on the same DEM, run in turn (A B A B ...) so that the
# machine's drift falls on both; prints each pair's wall times and ratio, and the median
# ratio, on a synthetic 1000x1000 Vesta tile and a synthetic 1440x720 global grid (1 M
# pixels each).
#   tests/bench/bench_landforms.sh [build-dir] [pairs]
set -euo pipefail
build="${1:-build}"
pairs="${2:-5}"
terrain="$build/tools/terrain"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$terrain" synth -q --width 1000 --height 1000 -o "$work/tile.lbl"
/usr/bin/python3 "$here/make_global_dem.py" "$work/global.tif" 1440 2> /dev/null

wall() {  # wall seconds of one terrain segment run with the given options
  rm -rf "$work/out"
  /usr/bin/time -f "%e" -o "$work/time" "$terrain" segment -q "$1" -o "$work/out" "${@:2}" > /dev/null
  cat "$work/time"
}

for dem in "$work/tile.lbl" "$work/global.tif"; do
  echo "$(basename "$dem"): default against --area-ratio 0.5 --persistence 10, $(nproc) cores"
  ratios=()
  for ((k = 1; k <= pairs; k++)); do
    a=$(wall "$dem")
    b=$(wall "$dem" --area-ratio 0.5 --persistence 10)
    r=$(echo "scale=3; $a / $b" | bc)
    ratios+=("$r")
    echo "  pair $k: default ${a} s, paper ${b} s, ratio $r"
  done
  median=$(printf '%s\n' "${ratios[@]}" | sort -n | sed -n "$(((pairs + 1) / 2))p")
  echo "  median ratio $median"
done
