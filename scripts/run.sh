#!/usr/bin/env bash
# Sets everything up (Debian packages via apt-get as root, then the build of the application)
# and runs the main job: `lpshoot solve` on the default scene, Elroy's beanie optimal control
# (examples/scenes/beanie.json). Results go to lpshoot-out/beanie/ (report.json,
# trajectory.csv, PNG plots).
#   bash scripts/run.sh [SCENE.json] [lpshoot options, e.g. --set horizon.N=400]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh lpshoot_cli
scene=examples/scenes/beanie.json
if [ $# -gt 0 ] && [[ "$1" == *.json ]]; then scene="$1"; shift; fi
command=solve
grep -q '"problem": *"beanie_free"' "$scene" && command=simulate
./build/examples/app/lpshoot "$command" "$scene" "$@"
