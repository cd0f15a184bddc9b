#!/usr/bin/env bash
# Configures and builds lpshoot (Release) in ./build with two parallel jobs.
set -euo pipefail
cd "$(dirname "$0")/.."
export CCACHE_BASEDIR="$PWD"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "${LPSHOOT_JOBS:-2}"
