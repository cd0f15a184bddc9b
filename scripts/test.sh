#!/usr/bin/env bash
# Sets everything up (Debian packages via apt-get as root, then the build) and runs the tests;
# then the core and shooting tests again in the checked build (Debug + ASan + UBSan).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
(cd build && ctest --output-on-failure -j "${LPSHOOT_JOBS:-2}")
bash scripts/test_checked.sh
