#!/usr/bin/env bash
# terrain's set-up, in one command each (see README.md):
#   ./setup.sh          install missing Debian packages, build the library and the `terrain`
#                       program only, run the main job on the sample
#   ./setup.sh test     install missing Debian packages, build everything (tests, examples,
#                       benchmarks, the Python module), run the whole test suite
#   ./setup.sh bench    also install the bench-only packages, build everything, run the benchmarks
#   ./setup.sh qgis     also install QGIS, build the program and the Python module, install the
#                       Processing provider into the QGIS profile (QGIS_PROFILE, default: the
#                       user's default profile)
#   ./setup.sh fuzz [SECONDS]  build the libFuzzer targets with clang in build-fuzz and run
#                       each for SECONDS (default 120) on its seeds (docs/robustness.md)
# All are idempotent: installed packages are skipped and the build directory is reused.
# Environment: BUILD_DIR (default build), OUT_DIR (default out), JOBS (default nproc).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$here"
mode="${1:-run}"
build_dir="${BUILD_DIR:-build}"
out_dir="${OUT_DIR:-out}"
jobs="${JOBS:-$(nproc)}"

# Every Debian 12 package the project builds, tests and runs with. Keep in step with
# cmake/TerrainDependencies.cmake, which names the package for each missing dependency.
packages=(
  build-essential cmake ninja-build pkg-config ccache
  libgdal-dev gdal-bin libproj-dev
  libgeographiclib-dev
  libcgal-dev libgmp-dev libmpfr-dev
  libfreetype-dev
  libboost-program-options-dev
  libeigen3-dev libtbb-dev
  # `mpirun -np N terrain segment` (docs/scale.md, "Ranks").
  libopenmpi-dev openmpi-bin
  catch2
  time
  fonts-dejavu-core
  # The Python module and its tests (docs/python.md).
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest
  python3-gdal python3-geopandas python3-rasterio python3-networkx
  # DataArrays in and out of the module, dask chunks (docs/python.md, "xarray").
  python3-xarray python3-rioxarray python3-dask
  # The tutorial notebook, docs/tutorial.ipynb, run by the tests (python3's kernel).
  python3-matplotlib python3-nbclient python3-nbconvert python3-ipykernel
)
# For `./setup.sh test` (the headless test of the QGIS provider, ~3 min to install) and
# `./setup.sh qgis`; the default set-up does not download QGIS.
qgis_packages=(qgis python3-qgis)
# Only for `./setup.sh bench`: libcgal-demo ships CGAL's sample meshes (data.tar.gz), on
# which bench_sdf compares our Shape Diameter Function with CGAL's.
bench_packages=(libcgal-demo)
# Closed meshes from that archive (cactus is CGAL's own SDF example).
bench_meshes=(cactus hand elephant cow dino homer bull camel man armadillo)

# install_packages PACKAGE...: installs those not installed yet.
install_packages() {
  local missing=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "setup: installing ${missing[*]}"
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "setup: run as root or install: ${missing[*]}" >&2; exit 1; }
    sudo=sudo
  fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# build [TARGET...]: configures the build directory once, then builds the targets named
# (none: every target).
build() {
  local launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  # Paths relative to the clone in ccache's keys: another clone of the same code (a CI run,
  # a worktree) finds this one's objects.
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$here}"
  if [ ! -f "$build_dir/CMakeCache.txt" ]; then
    cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}"
  fi
  local targets=()
  [ $# -gt 0 ] && targets=(--target "$@")
  cmake --build "$build_dir" -j "$jobs" "${targets[@]}"
}

case "$mode" in
  run)
    install_packages "${packages[@]}"
    # The main job needs the program alone (terrain_cli, which pulls in the library); the
    # tests, examples, benchmarks and Python module wait for `./setup.sh test`.
    build terrain_cli
    # The main job: the synthetic Vesta HAMO tile segmented with the defaults: landforms at
    # their own scale (the shape index at the radius chosen per pixel, regions down to 20
    # pixels; docs/segment.md). The paper's terrain parameters are --persistence 10
    # --area-ratio 0.5 --cost graph --saddle-penalty 20.
    sample=examples/data/vesta_hamo_tile.lbl
    mkdir -p "$out_dir"
    "$build_dir/tools/terrain" info "$sample"
    "$build_dir/tools/terrain" segment "$sample" -o "$out_dir/vesta_hamo_tile" --overwrite \
      --timings
    echo "setup: outputs in $out_dir/vesta_hamo_tile/ (labels.tif, regions.geojson, adjacency.*, preview.png, run.json)"
    ;;
  test)
    install_packages "${packages[@]}" "${qgis_packages[@]}"
    build
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs"
    ;;
  bench)
    install_packages "${packages[@]}" "${bench_packages[@]}"
    build
    archive="$(dpkg -L libcgal-demo | grep '/data\.tar\.gz$' | head -n 1)"
    mesh_dir="$build_dir/cgal-meshes"
    mkdir -p "$mesh_dir"
    meshes=() missing=()
    for m in "${bench_meshes[@]}"; do
      meshes+=("$mesh_dir/$m.off")
      [ -f "$mesh_dir/$m.off" ] || missing+=("data/meshes/$m.off")
    done
    [ ${#missing[@]} -eq 0 ] ||
      tar -xzf "$archive" -C "$mesh_dir" --strip-components=2 "${missing[@]}"
    "$build_dir/tests/bench/bench_mesh"
    "$build_dir/tests/bench/bench_field"
    "$build_dir/tests/bench/bench_sdf" "${meshes[@]}"
    "$build_dir/tests/bench/bench_reeb"
    "$build_dir/tests/bench/bench_grow"
    "$build_dir/tests/bench/bench_outputs"
    "$build_dir/tests/bench/bench_random_access"
    tests/bench/bench_segment.sh "$build_dir"
    ;;
  qgis)
    install_packages "${packages[@]}" "${qgis_packages[@]}"
    build terrain_cli terrain_python
    # The plugin, with local.json telling it where this build's module and program are.
    profile="${QGIS_PROFILE:-$HOME/.local/share/QGIS/QGIS3/profiles/default}"
    plugin="$profile/python/plugins/terrain_provider"
    mkdir -p "$(dirname "$plugin")"
    rm -rf "$plugin"
    cp -r qgis/terrain_provider "$plugin"
    printf '{"pythonpath": "%s", "cli": "%s"}\n' "$here/$build_dir/python" \
      "$here/$build_dir/tools/terrain" >"$plugin/local.json"
    qgis_process="$(command -v qgis_process.bin || echo /usr/bin/qgis_process.bin)"
    QT_QPA_PLATFORM=offscreen "$qgis_process" plugins enable terrain_provider >/dev/null
    echo "setup: the terrain provider is in $plugin (Processing toolbox > terrain)"
    ;;
  fuzz)
    install_packages "${packages[@]}" clang
    seconds="${2:-120}"
    fuzz_dir="${FUZZ_BUILD_DIR:-build-fuzz}"
    clang="$(command -v clang++-14 || command -v clang++)"
    launcher=()
    command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
    if [ ! -f "$fuzz_dir/CMakeCache.txt" ]; then
      cmake -S . -B "$fuzz_dir" -G Ninja -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS=-O1 -DCMAKE_CXX_COMPILER="$clang" \
        -DTERRAIN_FUZZ=ON \
        "${launcher[@]}"
    fi
    cmake --build "$fuzz_dir" -j "$jobs"
    # Working corpora grow in the build directory; the seeds stay in tests/fuzz/seeds (small
    # inputs: a 16x16 GeoTIFF reads in milliseconds, the 100 KB samples took 50 times longer).
    # Inputs are capped at a few times the largest seed; the campaigns run under nice.
    for target in ply off obj dem pds; do
      corpus="$fuzz_dir/corpus/$target"
      mkdir -p "$corpus" "$fuzz_dir/findings/$target"
      cp -n tests/fuzz/seeds/"$target"/* "$corpus/"
      binary="$fuzz_dir/tests/fuzz/fuzz_$target"
      max_len=16384
      dict=()
      case "$target" in
        ply | off | obj) binary="$fuzz_dir/tests/fuzz/fuzz_mesh_$target" max_len=4096 ;;
        pds) max_len=8192 dict=(-dict=tests/fuzz/pds.dict) ;;
      esac
      echo "setup: fuzzing $target for ${seconds}s"
      ASAN_OPTIONS=detect_leaks=1 nice -n 19 "$binary" "$corpus" -max_total_time="$seconds" \
        -rss_limit_mb=2048 -timeout=10 -max_len="$max_len" -print_final_stats=1 "${dict[@]}" \
        -artifact_prefix="$fuzz_dir/findings/$target/" 2>&1 | tail -n 14 ||
        echo "setup: fuzz_$target stopped on a finding (above)"
    done
    echo "setup: findings (crashes, leaks, timeouts, out-of-memory) in $fuzz_dir/findings/"
    ;;
  *)
    echo "usage: ./setup.sh [run|test|bench|qgis|fuzz [SECONDS]]" >&2
    exit 2
    ;;
esac
