#!/usr/bin/env bash
# Benchmark: `terrain segment` end to end (read, mesh, field, Reeb graph, simplification,
# region growing, every output) on a synthetic 1000x1000 Vesta tile; prints the wall time,
# the peak memory (maximum resident set) and the bytes per vertex.
#   tests/bench/bench_segment.sh [build-dir] [size]
set -euo pipefail
build="${1:-build}"
size="${2:-1000}"
terrain="$build/tools/terrain"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$terrain" synth -q --width "$size" --height "$size" -o "$work/tile.lbl"
for run in 1 2 3; do
  rm -rf "$work/out"
  /usr/bin/time -f "%e %M" -o "$work/time" "$terrain" segment -q "$work/tile.lbl" -o "$work/out" \
    --timings > "$work/stdout"
  read -r wall rss_kb < "$work/time"
  vertices=$((size * size))
  echo "run $run: ${wall} s wall, peak $((rss_kb / 1024)) MiB, $((rss_kb * 1024 / vertices)) bytes/vertex ($(nproc) cores)"
done
cat "$work/stdout"
