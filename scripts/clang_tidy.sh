#!/usr/bin/env bash
# clang-tidy with the checked-in .clang-tidy over the tree, against the release build's compile
# database (build/release/compile_commands.json, configured if missing), two files at a time.
#   scripts/clang_tidy.sh                 # the whole tree (CLEAN below)
#   scripts/clang_tidy.sh sim apps/x.cpp  # those directories or files
#   JOBS=1 scripts/clang_tidy.sh          # parallel jobs (default 2)
# Prints each finding once (a header's finding is reported by every file that includes it) and
# exits 1 if there is any, 0 with "clang-tidy: N files clean" otherwise. Uses run-clang-tidy when
# it is installed, else clang-tidy under xargs -P. fuzz/ is built only by the fuzz preset (clang,
# its own flags) and is not in the release database.
set -euo pipefail
cd "$(dirname "$0")/.."

# What is kept clean (checked 2026-12-03 with clang-tidy 14): the whole tree, i.e. every file of the
# release compile database but fuzz/: the library layers' sources, the server, the apps, the
# benchmarks, the tests (tests/.clang-tidy: the root config without the memcmp check, whose
# bit-for-bit comparisons are the determinism tests' point) and the engine's templates through all
# sixteen generated variants (each instantiates sim/src/engine/*.hpp with other arguments). A new
# directory with sources goes here too.
CLEAN=(sim/src sim/engine_variants turtle_runtime controllers world_files formats server apps bench tests)

[ -f build/release/compile_commands.json ] || cmake --preset release >/dev/null
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=("${CLEAN[@]}")

# db_files under|outside DIR|FILE...: the database's files under the targets, or those under none of
# them. Files generated into build/release/ count as their source directory's: the engine variants
# (build/release/sim/engine_variants/, where the engine's templates are instantiated) as
# sim/engine_variants/, apps/turtlegas/version_info.cpp as apps'.
db_files() {
  python3 - "$PWD" "$@" <<'EOF'
import json, os, sys
root, mode, targets = sys.argv[1], sys.argv[2], sys.argv[3:]
db = json.load(open(os.path.join(root, "build/release/compile_commands.json")))
out = []
for e in db:
    f = os.path.normpath(os.path.join(e["directory"], e["file"]))
    rel = os.path.relpath(f, root)
    rel_as = rel[len("build/release/"):] if rel.startswith("build/release/") else rel
    if rel.startswith("fuzz/"):
        continue
    under = any(rel_as == t or rel_as.startswith(t + "/") or rel == t for t in map(os.path.normpath, targets))
    if under == (mode == "under"):
        out.append(f if mode == "under" else rel_as)
print("\n".join(sorted(set(out))))
EOF
}
if [ $# -eq 0 ]; then
  mapfile -t outside < <(db_files outside "${CLEAN[@]}" | sed '/^$/d')
  if [ ${#outside[@]} -gt 0 ]; then
    echo "clang-tidy: not under CLEAN, add their directories to it: ${outside[*]}" >&2
    exit 2
  fi
fi
mapfile -t files < <(db_files under "${targets[@]}" | sed '/^$/d')
if [ ${#files[@]} -eq 0 ]; then
  echo "clang-tidy: no files in build/release/compile_commands.json under: ${targets[*]}" >&2
  exit 2
fi

jobs=${JOBS:-2}
# g++'s -Wno-restrict is unknown to clang: not a finding.
extra=(-extra-arg=-Wno-unknown-warning-option)
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if command -v run-clang-tidy >/dev/null; then
  regex="^($(printf '%s\n' "${files[@]}" | sed 's/[.[\*^$()+?{|]/\\&/g' | paste -sd'|'))\$"
  nice run-clang-tidy -p build/release -j "$jobs" -quiet "${extra[@]}" "$regex" >"$log" 2>&1 || true
else
  printf '%s\n' "${files[@]}" |
    nice xargs -P "$jobs" -n 1 clang-tidy -p build/release --quiet --extra-arg=-Wno-unknown-warning-option >"$log" 2>&1 || true
fi
findings=$(sed "s/\x1b\[[0-9;]*m//g" "$log" | grep -E '^[^ ].*:[0-9]+:[0-9]+: (warning|error):' | sort -u || true)
if [ -n "$findings" ]; then
  echo "$findings"
  echo "clang-tidy: $(wc -l <<<"$findings") findings in ${#files[@]} files" >&2
  exit 1
fi
if grep -qE 'clang-tidy.*(crashed|failed)|error: unable|Error while processing' "$log"; then
  grep -E 'crashed|failed|Error while processing' "$log" | head >&2
  exit 1
fi
echo "clang-tidy: ${#files[@]} files clean"
