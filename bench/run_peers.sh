#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
#
# turtlegas side by side with the best event-driven code and with Box2D, interleaved (A B, B A, ...)
# in one run on this machine: builds gas_bench and turtlegas (Release, build-bench/), the peers
# from ../shared/peers/ (into build-peers/, outside the source tree), runs bench/peers_bench.py,
# writes the JSON lines to docs/bench/peers-DATE-HOST-COMMIT.jsonl (moved there only once every
# round has run) and regenerates the side-by-side tables in docs/performance.md and the plot
# docs/bench/peers.svg with bench/make_peers.py.
#
#   bash bench/run_peers.sh            # everything: 9 periodic points x 5 rounds, Box2D, scaling
#                                      # (about 1 h on a quiet 2-core machine)
#   bash bench/run_peers.sh --quick    # N = 10^4 only, 2 short rounds: checks the script (~1 min);
#                                      # results in build-peers/quick/, docs/ left alone
#
# Environment (defaults in brackets):
#   POINTS       edmd points, N<n>_phi<f> [all nine of N 1e4,1e5,1e6 x phi 0p05,0p30,0p45]
#   ROUNDS       rounds [5]                  COLLISIONS   collisions per timed run [3e6]
#   PEERS        EDMD programs [cell_tuned_o3,cell_tuned_ofast]: the 2-D cell-list port with its
#                tuned settings, built -O3 and with its Makefile's -Ofast -march=native; the tables
#                compare turtlegas with the faster of them at each point
#   SETS         edmd (EDMD peer), box2d (step mode against Box2D), scaling (turtlegas alone at
#                N = 10^3 and 10^6, walled) [all three]
#   BOX2D_POINTS N<n>_phi<f>_dt<n> [N = 10^4, phi 0.05 and 0.30, dt = 1/60 and 1/600: target 4]
#                (SETS=box2d alone is about 1 CPU-minute at 5 rounds). The generated block of
#                docs/performance.md gets the sets of this run only: after a run of some of them,
#                put its tables elsewhere (bench/make_peers.py RESULTS prints them) and restore it
#   BALL_STEPS   per Box2D / step-mode run [3e6]
#   SCALING_ROUNDS [3]
#   PER_DISC     collisions per disc of the shared start's equilibration [10]
#   CORE         taskset core, empty for none [1]
#   PEERS_DIR    the peers' sources [../shared/peers beside the checkout, or beside the main
#                checkout when this is a git worktree]
#   BUILD_DIR    turtlegas build [build-bench]; an existing Release build is reused as it is
#   PEER_BUILD   [build-peers]; its starts/ keeps the equilibrated starts between runs
#
# Box2D comes from Debian's libbox2d-dev; it is installed here if missing (apt-get, as root or
# through sudo), as scripts/install-deps.sh would. Only the benchmarks need it.
set -euo pipefail

# The whole script is one function, read before any of it runs: editing the file during a long run
# cannot change what the run does.
main() {
  root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
  build=${BUILD_DIR:-$root/build-bench}
  peer_build=${PEER_BUILD:-$root/build-peers}
  peers_dir=${PEERS_DIR:-$root/../shared/peers}
  if [[ -z ${PEERS_DIR:-} && ! -d $peers_dir ]]; then
    # A git worktree (../wt/NAME) sits one level deeper than the main checkout: look beside that.
    common=$(git -C "$root" rev-parse --path-format=absolute --git-common-dir 2>/dev/null || true)
    [[ -n $common ]] && peers_dir=$(dirname "$(dirname "$common")")/shared/peers
  fi
  quick=0
  if [[ ${1:-} == --quick ]]; then quick=1; fi

  if [[ ! -f $peers_dir/smallenburg_edmd/build.sh ]]; then
    echo "run_peers.sh: no peers in $peers_dir (set PEERS_DIR to the folder holding smallenburg_edmd/)" >&2
    exit 2
  fi
  source "$root/bench/bench_lib.sh"

  if [[ ! -f $build/CMakeCache.txt ]]; then
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF > /dev/null
  fi
  cmake --build "$build" --target gas_bench turtlegas
  mkdir -p "$peer_build"
  sets=${SETS:-edmd,box2d,scaling}
  # The EDMD peers only for the set that runs them.
  if [[ ,$sets, == *,edmd,* ]]; then bash "$peers_dir/smallenburg_edmd/build.sh" "$peer_build/smallenburg" > /dev/null; fi
  box2d_build "$peer_build/box2d_gas"

  stamp=$(date -u +%Y-%m-%d)
  host=$(hostname -s 2>/dev/null || echo host)
  commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)
  args=(--tg-build "$build" --peer-build "$peer_build/smallenburg" --box2d "$peer_build/box2d_gas"
        --work "$peer_build/starts" --sets "$sets" --peers "${PEERS:-cell_tuned_o3,cell_tuned_ofast}"
        --per-disc "${PER_DISC:-10}" --core "${CORE-1}")
  if (( quick )); then
    out_dir=$peer_build/quick
    args+=(--points "${POINTS:-N1e4_phi0p05,N1e4_phi0p30,N1e4_phi0p45}" --rounds "${ROUNDS:-2}"
           --collisions "${COLLISIONS:-3e5}" --box2d-points "${BOX2D_POINTS:-N1e4_phi0p30_dt60}"
           --ball-steps "${BALL_STEPS:-1e6}" --scaling-points N1e3_phi0p05,N1e4_phi0p05
           --scaling-rounds "${SCALING_ROUNDS:-1}")
  else
    out_dir=$root/docs/bench
    [[ -n ${POINTS:-} ]] && args+=(--points "$POINTS")
    [[ -n ${BOX2D_POINTS:-} ]] && args+=(--box2d-points "$BOX2D_POINTS")
    args+=(--rounds "${ROUNDS:-5}" --collisions "${COLLISIONS:-3e6}" --ball-steps "${BALL_STEPS:-3e6}"
           --scaling-rounds "${SCALING_ROUNDS:-3}")
  fi
  mkdir -p "$out_dir"
  results=$out_dir/peers-$stamp-$host-$commit.jsonl
  machine=$out_dir/peers-$stamp-$host-$commit.machine.json
  # Both files are written beside the builds and moved into place only when every round has run.
  tmp=$peer_build/peers-running.jsonl
  bash "$root/bench/machine_json.sh" "$build" > "$tmp.machine"

  start=$SECONDS
  trap 'rm -f "$tmp" "$tmp.machine"' EXIT
  python3 "$root/bench/peers_bench.py" "${args[@]}" --out "$tmp"
  mv "$tmp.machine" "$machine"
  mv "$tmp" "$results"
  trap - EXIT
  echo "$(( SECONDS - start )) s; results in $results" >&2

  report make_peers.py "$results" "$machine" "$quick" "$root/docs/bench/peers.svg"
}

main "$@"
