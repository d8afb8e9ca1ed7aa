#!/usr/bin/env bash
# Fuzzes each libFuzzer harness (fuzz/) for SECONDS (default 60), one after another or, with
# JOBS=N, all at once; corpora live in build/fuzz/corpus/NAME (seeded on the first run: the world
# harnesses from worlds/ and fuzz/seeds/worlds/, cli_fuzz and protocol_fuzz from fuzz/seeds/NAME) and findings in
# build/fuzz/findings/NAME. Prints each harness's executions and coverage.
#   scripts/fuzz.sh 1800                              # 30 minutes each
#   JOBS=2 scripts/fuzz.sh 1800                       # all at once
#   HARNESSES="cli_fuzz protocol_fuzz" scripts/fuzz.sh 1800   # only these
# A finding (crash-*, timeout-*, oom-*) becomes a regression test: reproduce it with
#   build/fuzz/fuzz/NAME build/fuzz/findings/NAME/crash-...
# and, once fixed, keep it in fuzz/regressions/NAME/, which every run replays first.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD  # absolute paths: the cli and protocol harnesses work in a temporary directory of their own
seconds=${1:-60}
jobs=${JOBS:-1}
read -r -a harnesses <<<"${HARNESSES:-world_fuzz expect_fuzz cli_fuzz protocol_fuzz}"


cmake --preset fuzz >/dev/null
cmake --build --preset fuzz

for h in "${harnesses[@]}"; do
  corpus=build/fuzz/corpus/$h
  mkdir -p "$corpus" "build/fuzz/findings/$h"
  if [ -z "$(ls -A "$corpus")" ]; then
    if [ -d "fuzz/seeds/$h" ]; then
      # Argument vectors from docs/cli.md and the README; protocol sessions from docs/protocol.md.
      cp fuzz/seeds/"$h"/* "$corpus/"
    else
      # Seeds: the repository's world files, but not the benchmarks' (10^4 balls and more: slow,
      # and nothing the small ones do not reach).
      find worlds controllers/examples -name '*.json' -not -path 'worlds/bench/*' -exec cp {} "$corpus/" \;
      # And inputs no world file of the tree is: JSON nested past the 512-level limit in an x- key,
      # a recording's header line (docs/recording.md).
      cp fuzz/seeds/worlds/* "$corpus/"
    fi
  fi
done

# Earlier findings (fuzz/regressions/NAME/, one file each) run once first, with the same timeout:
# a finding that comes back stops the script before any fuzzing.
for h in "${harnesses[@]}"; do
  if [ -d "fuzz/regressions/$h" ]; then
    "build/fuzz/fuzz/$h" -timeout=10 -rss_limit_mb=2048 fuzz/regressions/"$h"/* >"build/fuzz/findings/$h/regressions.log" 2>&1 ||
      { echo "$h: an earlier finding is back (build/fuzz/findings/$h/regressions.log)" >&2; exit 1; }
    echo "$h: $(find "fuzz/regressions/$h" -type f | wc -l) earlier findings pass"
  fi
done

run_one() {
  local h=$1
  local log=build/fuzz/findings/$h/fuzz.log
  # -fork=1: the fuzzing runs in a child that is restarted after a finding, so a crash or a hang
  # (-timeout: an input running longer than 10 s) is saved and fuzzing goes on; -rss_limit_mb:
  # 2 GB is a memory finding. The bounded run of each input is in fuzz/fuzz_common.hpp.
  "$root/build/fuzz/fuzz/$h" "$root/build/fuzz/corpus/$h" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
    -artifact_prefix="$root/build/fuzz/findings/$h/" >"$log" 2>&1 || true
  # The last status line: "#EXECS: cov: EDGES ft: FEATURES corp: ..."
  local last execs cov ft
  last=$(grep -E '^#[0-9]+:? .*cov: ' "$log" | tail -1 || true)
  execs=$(sed -E 's/^#([0-9]+).*/\1/' <<<"$last")
  cov=$(grep -oE 'cov: [0-9]+' <<<"$last" | grep -oE '[0-9]+' || echo "?")
  ft=$(grep -oE 'ft: [0-9]+' <<<"$last" | grep -oE '[0-9]+' || echo "?")
  local found
  found=$(find "build/fuzz/findings/$h" -name 'crash-*' -o -name 'timeout-*' -o -name 'oom-*' -o -name 'leak-*' | wc -l)
  echo "$h: ${seconds} s, $execs executions, coverage $cov edges ($ft features), $found findings (log $log)"
}

if [ "$jobs" -gt 1 ]; then
  for h in "${harnesses[@]}"; do run_one "$h" & done
  wait
else
  for h in "${harnesses[@]}"; do run_one "$h"; done
fi
