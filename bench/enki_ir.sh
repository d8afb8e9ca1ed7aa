#!/usr/bin/env bash
# The e-puck swarm against Enki (issue 34 §6; docs/performance.md "The e-puck swarm against Enki"):
# builds bench/enki_ir/enki_epuck.cpp against Debian's Enki (apt-get install -y libenki-dev) and
# runs it and turtlegas's bench/epuck_bench alternately on one pinned core, PAIRS pairs of STEPS
# control steps (dt 0.1 s) for each N (A B, then B A, ...). Prints each run's JSON line, then per N
# the medians and the median of the pairs' ratios (turtle-steps per CPU second, turtlegas / Enki).
#
#   bash bench/enki_ir.sh BUILD_DIR "100 1000 10000" [PAIRS: 3] [STEPS: 300 for N <= 1000, else 30]
#   env: CORE (default 1), RAYS (turtlegas ring, default 8), ENKI_SENSORS (ir|none|default; default ir),
#        TG_SENSE (on|off|read, default on), OUT (enki_epuck's build dir, default /tmp/enki-ir-build)
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
TG="$(cd "${1:?usage: enki_ir.sh BUILD_DIR \"N...\" [PAIRS] [STEPS]}" && pwd)"
SIZES="${2:-100 1000 10000}"
PAIRS="${3:-3}"
CORE="${CORE:-1}"
RAYS="${RAYS:-8}"
ENKI_SENSORS="${ENKI_SENSORS:-ir}"
TG_SENSE="${TG_SENSE:-on}"
OUT="${OUT:-/tmp/enki-ir-build}"
[ -f /usr/include/enki/PhysicalEngine.h ] || { echo "enki_ir.sh: Enki headers missing: apt-get install -y libenki-dev" >&2; exit 2; }
[ -x "$TG/bench/epuck_bench" ] || { echo "enki_ir.sh: $TG/bench/epuck_bench not found (cmake --build $TG --target epuck_bench)" >&2; exit 2; }
mkdir -p "$OUT"
g++ -std=c++17 -O2 -Wall -Wextra -o "$OUT/enki_epuck" "$HERE/enki_ir/enki_epuck.cpp" -lenki
RUNS="$(mktemp /tmp/enki-ir.XXXXXX.jsonl)"
for N in $SIZES; do
  STEPS="${4:-}"
  if [ -z "$STEPS" ]; then if [ "$N" -le 1000 ]; then STEPS=300; else STEPS=30; fi; fi
  echo "# N=$N, $PAIRS pairs of $STEPS steps, core $CORE, $(date -u +%FT%TZ), load $(cut -d' ' -f1-3 /proc/loadavg)"
  tg() { echo "{\"program\":\"turtlegas\",\"n\":$N,\"pair\":$1,\"run\":$(taskset -c "$CORE" "$TG/bench/epuck_bench" --turtles "$N" --steps "$STEPS" --rays "$RAYS" --sense "$TG_SENSE")}" | tee -a "$RUNS"; }
  en() { echo "{\"program\":\"enki\",\"n\":$N,\"pair\":$1,\"run\":$(taskset -c "$CORE" "$OUT/enki_epuck" "$N" "$STEPS" --sensors "$ENKI_SENSORS")}" | tee -a "$RUNS"; }
  for ((p = 1; p <= PAIRS; p++)); do
    if ((p % 2)); then tg "$p"; en "$p"; else en "$p"; tg "$p"; fi
  done
done
/usr/bin/python3 - "$RUNS" <<'PY'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
def rate(r):
    x = r["run"]
    return x["turtle_steps_per_cpu_second"] if r["program"] == "turtlegas" else x["robot_steps_per_cpu_second"]
print("| N | turtlegas steps/CPU-s (min-max) | Enki steps/CPU-s (min-max) | turtlegas/Enki, median of pairs (range) | mean speed tg / Enki | contacts/turtle-s tg, Enki collision events/robot-s |")
print("|---:|---:|---:|---:|---:|---:|")
for n in sorted({r["n"] for r in rows}):
    tg = {r["pair"]: r for r in rows if r["n"] == n and r["program"] == "turtlegas"}
    en = {r["pair"]: r for r in rows if r["n"] == n and r["program"] == "enki"}
    ratios = [rate(tg[p]) / rate(en[p]) for p in sorted(tg) if p in en]
    a = [rate(r) for r in tg.values()]; b = [rate(r) for r in en.values()]
    med = statistics.median
    print(f"| {n} | {med(a):.4g} ({min(a):.3g}-{max(a):.3g}) | {med(b):.4g} ({min(b):.3g}-{max(b):.3g}) | "
          f"**{med(ratios):.3g}** ({min(ratios):.3g}-{max(ratios):.3g}) | "
          f"{med([r['run']['mean_speed'] for r in tg.values()]):.3g} / {med([r['run']['mean_speed'] for r in en.values()]):.3g} | "
          f"{med([r['run']['contacts_per_turtle_second'] for r in tg.values()]):.3g}, {med([r['run']['collision_events_per_robot_second'] for r in en.values()]):.3g} |")
PY
rm -f "$RUNS"
