#!/usr/bin/env bash
# Configures and builds lpshoot (Release) in ./build, with scripts/jobs.sh's parallel jobs (one
# per core, within the memory; LPSHOOT_JOBS overrides).
#   bash scripts/build.sh [TARGET ...]   (default: everything, tests and benchmarks included;
#                                         LPSHOOT_BUILD_BENCH=OFF leaves the benchmarks out)
set -euo pipefail
cd "$(dirname "$0")/.."
export CCACHE_BASEDIR="$PWD"
jobs=$(bash scripts/jobs.sh)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DLPSHOOT_BUILD_BENCH="${LPSHOOT_BUILD_BENCH:-ON}" >/dev/null
if [ $# -eq 0 ]; then
  cmake --build build -j "$jobs"
else
  for target in "$@"; do cmake --build build -j "$jobs" --target "$target"; done
fi
