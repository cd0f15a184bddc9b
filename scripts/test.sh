#!/usr/bin/env bash
# Sets everything up (Debian packages via apt-get as root, then the build) and runs the tests;
# then the core and shooting tests again in the checked build (Debug + ASan + UBSan).
# The benchmarks are not built here: they are not tests, and they were a quarter of the Release
# build's compile time (bench_galerkin_step.cpp and bench_scaling.cpp alone ~4-8 min each on two
# cores); `bash scripts/build.sh` builds them (bench/RESULTS.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
LPSHOOT_BUILD_BENCH=OFF bash scripts/build.sh
jobs=$(bash scripts/jobs.sh)
(cd build && ctest --output-on-failure -j "$jobs")
bash scripts/test_checked.sh
