#!/usr/bin/env bash
# The checked build: Debug (Eigen's assertions on) with AddressSanitizer and
# UndefinedBehaviorSanitizer, in ./build-checked; runs the core and shooting tests of label
# "core_checked" (what CI runs: all the core tests but the five largest instances,
# tests/CMakeLists.txt), with --core all the core and shooting tests (labels core and
# core_checked), with --all every test (the application's and the fuzz test included).
#   bash scripts/test_checked.sh [--core | --all]
set -euo pipefail
cd "$(dirname "$0")/.."
export CCACHE_BASEDIR="$PWD"
# -O1: the sanitized suite runs in minutes rather than tens of minutes; assertions stay on.
# -g1: line tables only (the sanitizers' reports keep file and line); full debug information
# made the sanitized objects ~1.35x slower to compile (tests/test_momentum.cpp: 65 s against 48 s).
cmake -S . -B build-checked -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" \
  -DLPSHOOT_SANITIZE=address,undefined -DLPSHOOT_BUILD_BENCH=OFF >/dev/null
jobs=$(bash scripts/jobs.sh)
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
if [ "${1:-}" = "--all" ]; then
  cmake --build build-checked -j "$jobs"
  cd build-checked && ctest --output-on-failure -j "$jobs" --timeout 1800
elif [ "${1:-}" = "--core" ]; then
  cmake --build build-checked -j "$jobs" --target lpshoot_core_tests
  cd build-checked && ctest --output-on-failure -j "$jobs" -L core --timeout 1800
else
  cmake --build build-checked -j "$jobs" --target lpshoot_checked_tests
  cd build-checked && ctest --output-on-failure -j "$jobs" -L checked --timeout 1800
fi
