#!/usr/bin/env bash
# Benchmark: `terrain segment` against `gdaldem slope` on the same 1 M pixel DEM (a
# synthetic 1000 x 1000 Vesta tile, or the DEM given), run in turn (gdaldem, the defaults,
# the paper's single scale, gdaldem, ...) so that the machine's drift falls on all three;
# prints each round's wall times, the median ratio of each segment run to gdaldem's in its
# round, and the median share of the write stage (run.json's timings); then the medians of
# the two segment runs on a 64 x 64 synthetic tile: what a run costs whatever its size.
#   tests/bench/bench_gdaldem.sh [build-dir] [rounds] [DEM]
set -euo pipefail
build="${1:-build}"
rounds="${2:-5}"
terrain="$build/tools/terrain"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
dem="${3:-}"
if [ -z "$dem" ]; then
  "$terrain" synth -q --width 1000 --height 1000 -o "$work/tile.lbl" > /dev/null
  dem="$work/tile.lbl"
fi

seconds() {  # wall seconds of a command
  /usr/bin/time -f "%e" -o "$work/time" "$@" > /dev/null 2>&1
  cat "$work/time"
}
write_share() {  # the write stage's share of the run's stages, from run.json
  /usr/bin/python3 -c 'import json, sys
t = json.load(open(sys.argv[1]))["timings_seconds"]
print("%.2f" % (t["write"] / sum(v for k, v in t.items() if k != "total")))' "$work/out/run.json"
}

echo "$(basename "$dem"): terrain segment against gdaldem slope, $(nproc) cores"
printf "%5s %9s %9s %9s %8s %8s %7s %7s\n" round gdaldem default paper "def/gd" "pap/gd" "write%" "write%"
default_ratios=() paper_ratios=() default_writes=() paper_writes=()
for ((k = 1; k <= rounds; k++)); do
  rm -f "$work/slope.tif"
  g=$(seconds gdaldem slope -q "$dem" "$work/slope.tif")
  rm -rf "$work/out"
  d=$(seconds "$terrain" segment -q "$dem" -o "$work/out")
  dw=$(write_share)
  rm -rf "$work/out"
  p=$(seconds "$terrain" segment -q "$dem" -o "$work/out" --area-ratio 0.5 --persistence 10)
  pw=$(write_share)
  dr=$(awk -v a="$d" -v b="$g" 'BEGIN { printf "%.1f", a / b }')
  pr=$(awk -v a="$p" -v b="$g" 'BEGIN { printf "%.1f", a / b }')
  printf "%5d %9s %9s %9s %8s %8s %7s %7s\n" "$k" "$g" "$d" "$p" "$dr" "$pr" "$dw" "$pw"
  default_ratios+=("$dr") paper_ratios+=("$pr") default_writes+=("$dw") paper_writes+=("$pw")
done
median() { printf "%s\n" "$@" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
echo "median ratio to gdaldem slope: defaults $(median "${default_ratios[@]}"), paper's single scale $(median "${paper_ratios[@]}")"
echo "median share of the write stage: defaults $(median "${default_writes[@]}"), paper's single scale $(median "${paper_writes[@]}")"

# A run's cost whatever the DEM's size: the same commands on a 64 x 64 synthetic tile.
"$terrain" synth -q --width 64 --height 64 -o "$work/small.lbl" > /dev/null
small_default=() small_paper=()
for ((k = 1; k <= rounds; k++)); do
  rm -rf "$work/out"
  small_default+=("$(seconds "$terrain" segment -q "$work/small.lbl" -o "$work/out")")
  rm -rf "$work/out"
  small_paper+=("$(seconds "$terrain" segment -q "$work/small.lbl" -o "$work/out" \
    --area-ratio 0.5 --persistence 10)")
done
echo "64 x 64 tile, median wall seconds: defaults $(median "${small_default[@]}"), paper's single scale $(median "${small_paper[@]}")"
