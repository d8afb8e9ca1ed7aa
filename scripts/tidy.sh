#!/usr/bin/env bash
# Runs clang-tidy (.clang-tidy) on the project's sources, or on the files given, against the
# release build's compile database; exits non-zero on any warning.
#   scripts/tidy.sh                           # every .cpp of the tree (slow: a compile each)
#   scripts/tidy.sh apps/turtlegas/*.cpp      # some
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f build/release/compile_commands.json ] || cmake --preset release >/dev/null
if [ $# -gt 0 ]; then files=("$@"); else
  mapfile -t files < <(git ls-files '*.cpp' | grep -v '^fuzz/')
fi
out=$(clang-tidy -p build/release --quiet "${files[@]}" 2>/dev/null || true)
if grep -q 'warning:\|error:' <<<"$out"; then
  echo "$out"
  exit 1
fi
echo "tidy: ${#files[@]} files clean"
