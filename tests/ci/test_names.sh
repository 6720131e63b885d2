#!/usr/bin/env bash
# test_names.sh SOURCE_DIR: fails when a Catch2 test name holds a ';'. CTest's test
# discovery splits names at ';', and the pieces match no test: such a test never runs.
set -euo pipefail
found=$(grep -rPzlo 'TEST_CASE\(\s*"[^"]*;' "$1/tests" --include='*.cpp' | tr '\0' '\n' || true)
if [ -n "$found" ]; then
  echo "test names with ';' (CTest would never run them) in:" >&2
  echo "$found" >&2
  exit 1
fi
echo "no test name holds a ';'"
