#!/usr/bin/env bash
# Installs what turtlegas needs from Debian 12 packages, only what is missing.
# Runs apt-get as root (directly, or through sudo when not root).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  nlohmann-json3-dev libspdlog-dev libcli11-dev catch2
  libboost-dev libboost-context-dev   # libboost-dev: Asio and Beast (header-only) for server/
  python3
  python3-dev pybind11-dev python3-numpy   # the Python module (python/, docs/python.md)
  dpkg-dev binutils   # the Debian package: cpack (dpkg-shlibdeps), tests/package/deb_test.py (readelf)
  clang libclang-rt-14-dev clang-tidy   # the clang and fuzz presets, scripts/clang_tidy.sh
  libopenmpi-dev openmpi-bin   # turtlegas sweep under mpirun (optional at build time; its test runs mpirun)
  chromium   # the viewer's browser tests (tests/server/test_browser.py) and bench/viewer_bench.py, headless
  libcairo2-dev   # turtlegas render: PNG pictures and frames
)
# Optional: `turtlegas render --video` runs ffmpeg when it is installed (its test is skipped when
# not). Install it with: apt-get install ffmpeg

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

as_root=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null; then as_root=(sudo); else
    echo "install-deps: missing ${missing[*]}; run as root or install sudo" >&2
    exit 1
  fi
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
