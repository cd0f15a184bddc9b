#!/usr/bin/env bash
# Prints how many compile and test jobs to run in parallel: $LPSHOOT_JOBS when set, else one per
# core, at most one per 4 GB of available memory (the heaviest translation units peak at 2.9 GB,
# tests/test_galerkin_order8.cpp, and 3.8 GB, bench/bench_galerkin_step.cpp, in Release), at least 1.
set -euo pipefail
if [ -n "${LPSHOOT_JOBS:-}" ]; then echo "$LPSHOOT_JOBS"; exit 0; fi
cores=$(nproc 2>/dev/null || echo 2)
mem_kb=$(awk '/^MemAvailable:/ {print $2}' /proc/meminfo 2>/dev/null || echo 0)
by_memory=$(( mem_kb / 4000000 ))
jobs=$cores
[ "$by_memory" -gt 0 ] && [ "$by_memory" -lt "$jobs" ] && jobs=$by_memory
[ "$jobs" -lt 1 ] && jobs=1
echo "$jobs"
