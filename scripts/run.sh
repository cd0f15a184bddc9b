#!/usr/bin/env bash
# Sets everything up (Debian packages via apt-get as root, then the build) and runs the main
# job: Elroy's beanie stepped by the discrete Lagrange–Poincaré flow, with its momentum drift.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
./build/examples/beanie_drift "$@"
