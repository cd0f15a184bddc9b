#!/usr/bin/env bash
# Configures and builds lpshoot (Release) in ./build with two parallel jobs.
#   bash scripts/build.sh [TARGET ...]   (default: everything, tests and benchmarks included)
set -euo pipefail
cd "$(dirname "$0")/.."
export CCACHE_BASEDIR="$PWD"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
if [ $# -eq 0 ]; then
  cmake --build build -j "${LPSHOOT_JOBS:-2}"
else
  for target in "$@"; do cmake --build build -j "${LPSHOOT_JOBS:-2}" --target "$target"; done
fi
