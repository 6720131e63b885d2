#!/usr/bin/env bash
# Proves .ci/check-layers works: it passes on this tree, and fails, naming each file, on a
# copy of the tree with violations planted in algorithm layers (a GDAL header, an io/ header,
# a FreeType header in a public header, a private geo/ header, a relative include of
# another folder's file in any layer), while GDAL and geo's shared headers in io/ and geo/
# stay allowed.
#   tests/ci/check_layers.sh SOURCE_DIR WORK_DIR
set -euo pipefail
source_dir=$1
work=$2
check="$source_dir/.ci/check-layers"

fail() { echo "FAIL: $*" >&2; exit 1; }

"$check" "$source_dir" || fail "the check fails on the real tree"

rm -rf "$work"
mkdir -p "$work"
cp -r "$source_dir/.ci" "$source_dir/libterrain" "$work/"
"$work/.ci/check-layers" "$work" >/dev/null || fail "the check fails on an unchanged copy"

# Allowed: the same includes in io/ and geo/.
echo '#include <gdal_priv.h>' >> "$work/libterrain/src/io/read_dem.cpp"
echo '#include "terrain/internal/geo/iau_crs.hpp"' >> "$work/libterrain/src/io/read_dem.cpp"
"$work/.ci/check-layers" "$work" >/dev/null ||
  fail "io/ and geo/ may include GDAL headers and geo's shared headers"

plant() {  # plant FILE LINE: append LINE to FILE, expect the check to fail naming FILE
  local file=$1 line=$2 out rc=0
  cp "$work/libterrain/$file" "$work/saved"
  printf '%s\n' "$line" >> "$work/libterrain/$file"
  out=$("$work/.ci/check-layers" "$work" 2>&1) || rc=$?
  [[ $rc -eq 1 ]] || fail "planting '$line' in $file: exit $rc, expected 1"
  grep -qF "libterrain/$file:" <<<"$out" || fail "planting '$line' in $file: not named: $out"
  mv "$work/saved" "$work/libterrain/$file"
  echo "caught: $file: $line"
}
plant src/mesh/dem_to_mesh.cpp '#include <ogr_spatialref.h>'
plant src/segment/regions.cpp '#include "../io/lonlat_frame.hpp"'
plant src/field/vertex_field.cpp '#include "terrain/io/read_dem.hpp"'
plant src/core/dem.cpp '  #  include <cpl_conv.h>'
plant src/reeb/simplify.cpp '#include <proj.h>'
plant include/terrain/segment/regions.hpp '#include <ft2build.h>'
plant src/segment/pixel_areas.cpp '#include "../geo/ogr_support.hpp"'
plant include/terrain/mesh/dem_to_mesh.hpp '#include "terrain/geo/georeference.hpp"'
plant src/mesh/dem_to_mesh.cpp '#include "terrain/internal/geo/iau_crs.hpp"'
plant src/pipeline/segment.cpp '#include "../reeb/simplifier.hpp"'
plant src/io/read_dem.cpp '#include "../core/dem.cpp"'
plant src/field/sdf.cpp '#include "../mesh/mesh_lists.hpp"'

# A new file in an algorithm layer is checked too (the temporary exceptions name files).
echo '#include <gdal.h>' > "$work/libterrain/src/synth/planted.cpp"
rc=0
"$work/.ci/check-layers" "$work" >/dev/null || rc=$?
[[ $rc -eq 1 ]] || fail "a new synth file including gdal.h passed"
rm "$work/libterrain/src/synth/planted.cpp"
echo "caught: src/synth/planted.cpp: #include <gdal.h>"

# Restored: passes again.
"$work/.ci/check-layers" "$work" >/dev/null || fail "the check fails after restoring the copy"
echo "check-layers: passes on the tree, catches every planted include"
