#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
#
# Builds accuracy_bench (Release, build-bench/) and bench/box2d_gas.cpp (Box2D from Debian's
# libbox2d-dev, installed if missing; into build-peers/), runs exact mode and step mode at six dt on
# the ballistic scene, the memo's gas under gravity and the charged scene (one process, about 30 s),
# then exact mode, step mode and Box2D at dt = 1/60 ... 1/6000 on the walled gas at N = 10^3, 10^4
# and 10^5, phi = 0.3 (about 4 CPU-minutes a round), writes the JSON lines to docs/bench/accuracy-DATE-HOST-COMMIT.jsonl
# and regenerates the "What accuracy costs" tables and the plots docs/bench/accuracy.svg and
# docs/bench/accuracy_box2d.svg in docs/performance.md.
#
#   bash bench/run_accuracy.sh           # the full set
#   bash bench/run_accuracy.sh --quick   # T = 5 s, three dt, the walled gas at N = 10^3 only, two
#                                        # rounds: checks the script; leaves docs/ alone
#
# The walled gas runs in ROUNDS rounds (default 3), turtlegas (exact and step mode) and Box2D
# interleaved per scene: turtlegas first in even rounds, Box2D first in odd ones (A B, B A, ...).
# Every walled line gets its "round"; the errors are the same bits in every round (both codes are
# deterministic), the costs are not, and make_accuracy.py gives the median of each and takes the
# speed ratio of target 3 per round (median and range of the pairs).
#
# BUILD_DIR picks another build directory (an existing Release build is reused as it is);
# PEER_BUILD where box2d_gas goes (build-peers/); WALLED the walled scenes (comma-separated world
# files, default the three below); WALLED_DTS their step-mode and Box2D dt as 1/n (comma-separated
# n, default 60,200,600,2000,6000); ROUNDS the walled rounds; FIELD_SCENES=0 skips the ballistic,
# gas and charged scenes (extra rounds of the cheap points: WALLED_DTS=60 FIELD_SCENES=0 ROUNDS=4).
set -euo pipefail

# The whole script is one function, read before any of it runs: editing the file during a long run
# cannot change what the run does.
main() {
  root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
  source "$root/bench/bench_lib.sh"
  build=${BUILD_DIR:-$root/build-bench}
  quick=0
  if [[ ${1:-} == --quick ]]; then quick=1; fi

  if [[ ! -f $build/CMakeCache.txt ]]; then
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF > /dev/null
  fi
  cmake --build "$build" --target accuracy_bench

  stamp=$(date -u +%Y-%m-%d)
  host=$(hostname -s 2>/dev/null || echo host)
  commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)
  peer_build=${PEER_BUILD:-$root/build-peers}
  box2d_build "$peer_build/box2d_gas"
  states=$peer_build/accuracy-states
  walled_dts=(60 200 600 2000 6000)
  if (( quick )); then
    out_dir=$build/quick
    walled=(worlds/bench/gas_N1e3_phi0p30.json)
    walled_dts=(60 600)
    rounds=${ROUNDS:-2}
    min_cpu=0.1
    args=(--until 5 --dts 10,100,1000 --min-cpu "$min_cpu" --ball-seconds 2000)
  else
    out_dir=$root/docs/bench
    walled=(worlds/bench/gas_N1e3_phi0p30.json worlds/bench/gas_N1e4_phi0p30.json worlds/bench/gas_N1e5_phi0p30.json)
    min_cpu=1  # accuracy_bench's default
    args=()
    rounds=${ROUNDS:-3}
  fi
  if [[ -n ${WALLED:-} ]]; then IFS=, read -r -a walled <<< "$WALLED"; fi
  if [[ -n ${WALLED_DTS:-} ]]; then IFS=, read -r -a walled_dts <<< "$WALLED_DTS"; fi
  walled_args=(--ballistic "" --gas "" --charged "" --min-cpu "$min_cpu"
               --walled-dts "$(IFS=,; echo "${walled_dts[*]}")" --state-dir "$states")
  if (( quick )); then walled_args+=(--ball-seconds 2000); fi
  mkdir -p "$out_dir"
  results=$out_dir/accuracy-$stamp-$host-$commit.jsonl
  machine=$out_dir/accuracy-$stamp-$host-$commit.machine.json
  bash "$root/bench/machine_json.sh" "$build" > "$machine"

  start=$SECONDS
  # The field scenes once, from the repository root: the bench's default world files are relative
  # to it.
  if [[ ${FIELD_SCENES:-1} == 1 ]]; then
    (cd "$root" && "$build/bench/accuracy_bench" "${args[@]}") > "$results.tmp"
  else
    : > "$results.tmp"
  fi
  for (( round = 0; round < rounds; ++round )); do
    for w in "${walled[@]}"; do
      if (( round % 2 == 0 )); then
        walled_turtlegas "$w" "$round"
        walled_box2d "$w" "$round"
      else
        walled_box2d "$w" "$round"
        walled_turtlegas "$w" "$round"
      fi
    done
  done
  mv "$results.tmp" "$results"
  echo "$(( SECONDS - start )) s; results in $results" >&2

  report make_accuracy.py "$results" "$machine" "$quick" "$root/docs/bench/accuracy.svg" \
    --svg-box2d "$root/docs/bench/accuracy_box2d.svg"
}

# walled_turtlegas WORLD ROUND: exact mode, its twin and step mode at every dt on one walled scene
# (accuracy_bench --walled), which also writes the scene's start and exact mode's state at the
# horizon for Box2D (the same bits every round). Its lines, tagged with the round, go to
# $results.tmp.
walled_turtlegas() {
  (cd "$root" && "$build/bench/accuracy_bench" "${walled_args[@]}" --walled "$1") | tag_round "$2" >> "$results.tmp"
}

# walled_box2d WORLD ROUND: Box2D on one walled scene at every dt from the same start, positions
# compared with exact mode's at the same horizon, the run as long as turtlegas's (both from the
# scene's first exact-mode line), repeated like accuracy_bench's runs until they add up to min_cpu.
walled_box2d() {
  local w=$1 stem horizon until n
  stem=$(basename "$w" .json)
  read -r horizon until < <(python3 -c 'import json, sys
for line in open(sys.argv[1]):
    r = json.loads(line)
    if r["scene"] == "walled" and r["mode"] == "exact" and r["world_file"] == sys.argv[2]:
        print(repr(r["horizon"]), repr(r["sim_seconds"]))
        break' "$results.tmp" "$w")
  for n in "${walled_dts[@]}"; do
    "$peer_build/box2d_gas" "$states/$stem.start.sph" --dt "$(python3 -c "print(repr(1 / $n))")" --until "$until" \
      --reference "$states/$stem.reference.sph" --horizon "$horizon" --min-cpu "$min_cpu" --name "$w" |
      tag_round "$2" >> "$results.tmp"
    tail -n 1 "$results.tmp" | python3 -c 'import json, sys
r = json.load(sys.stdin)
print("round %s walled %s box2d dt=1/%s: %.3g cpu s, energy error %.3g, RMS position error %.3g" % (r["round"],
      sys.argv[1], sys.argv[2], r["cpu_seconds"], r["energy_error"], r["rms_position_error"]))' "$stem" "$n" >&2
  done
}

# tag_round ROUND: copies JSON lines from standard input to standard output with "round": ROUND added.
tag_round() {
  python3 -c 'import json, sys
for line in sys.stdin:
    if line.strip():
        r = json.loads(line)
        r["round"] = int(sys.argv[1])
        print(json.dumps(r), flush=True)' "$1"
}

main "$@"
