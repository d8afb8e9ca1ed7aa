# SPDX-License-Identifier: MIT
#
# What the bench/run_*.sh scripts share; they source this file.

# report SCRIPT RESULTS MACHINE QUICK SVG [PLOT OPTIONS...]: the tables of RESULTS by bench/SCRIPT,
# on standard output when QUICK is 1, otherwise into docs/performance.md between the script's
# GENERATED markers, and the plot into SVG (with further plots named by the options).
report() {
  local script=$1 results=$2 machine=$3 quick=$4 svg=$5
  shift 5
  local root
  root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
  if (( quick )); then
    python3 "$root/bench/$script" "$results" --machine "$machine"
  else
    python3 "$root/bench/$script" "$results" --machine "$machine" --doc "$root/docs/performance.md" --svg "$svg" "$@"
    echo "tables updated in docs/performance.md" >&2
  fi
}

# box2d_build OUT builds bench/box2d_gas.cpp into OUT against Debian's libbox2d-dev (Box2D 2.4),
# installing the package first if it is missing (apt-get, as root or through sudo). Only the
# benchmarks need Box2D, so it is neither in scripts/install-deps.sh nor in the CMake build.
box2d_build() {
  local out=$1
  if ! dpkg-query -W -f='${Status}' libbox2d-dev 2>/dev/null | grep -q "install ok installed"; then
    local as_root=()
    if [[ $(id -u) -ne 0 ]]; then
      if command -v sudo > /dev/null; then as_root=(sudo); else
        echo "box2d: libbox2d-dev is missing; install it as root: apt-get install libbox2d-dev" >&2
        return 2
      fi
    fi
    echo "box2d: installing libbox2d-dev (Debian's Box2D 2.4) for the Box2D benchmarks" >&2
    DEBIAN_FRONTEND=noninteractive "${as_root[@]}" apt-get install -y -qq --no-install-recommends libbox2d-dev >&2
  fi
  local src
  src=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/box2d_gas.cpp
  mkdir -p "$(dirname "$out")"
  if [[ ! -x $out || $src -nt $out ]]; then
    ${CXX:-g++} -std=c++17 -O2 -Wall -Wextra -o "$out" "$src" -lbox2d
  fi
}
