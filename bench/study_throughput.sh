#!/usr/bin/env bash
# Points per second of `lpshoot study` on a study of small solves (bench/RESULTS.md, issue 12):
# 1 and 2 threads, and 1 and 2 MPI ranks (when lpshoot was built with MPI), REPEAT runs each,
# the median reported. Usage: bench/study_throughput.sh [BUILD_DIR] [REPEAT]
set -euo pipefail
build=$(cd "${1:-build}" && pwd)
repeat=${2:-5}
lpshoot="$build/examples/app/lpshoot"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scenes=$(cd "$(dirname "$0")/../examples/scenes" && pwd)
# 256 beanie solves (N = 200, four-segment multiple shooting).
cat > "$work/study.json" <<JSON
{"scene": "$scenes/beanie.json",
 "axes": {"parameters.I1": {"from": 0.5, "to": 2.0, "count": 16}, "parameters.I2": {"from": 0.25, "to": 1.0, "count": 16}}}
JSON
points=256
mpirun=(mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && mpirun+=(--allow-run-as-root)

# One study run into a fresh directory: its wall time in seconds. Arguments: the launcher prefix
# (possibly empty) up to "--", then options for `lpshoot study`.
run() {
  local prefix=()
  while [ "$1" != "--" ]; do prefix+=("$1"); shift; done
  shift
  local out="$work/out-$RANDOM$RANDOM" start end
  start=$(date +%s.%N)
  "${prefix[@]}" "$lpshoot" study "$work/study.json" --out "$out" --no-plot --quiet "$@" > /dev/null || [ $? = 1 ]
  end=$(date +%s.%N)
  awk -v s="$start" -v e="$end" 'BEGIN { print e - s }'
}
report() {
  local label=$1; shift
  local times=() t
  for _ in $(seq "$repeat"); do times+=("$(run "$@")"); done
  t=$(printf '%s\n' "${times[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
  printf '%-16s median %6.3f s  %6.1f points/s   (runs: %s)\n' "$label" "$t" "$(awk -v p="$points" -v t="$t" 'BEGIN { print p / t }')" \
    "$(printf '%.3f ' "${times[@]}")"
}
echo "lpshoot study, $points beanie solves (N = 200), $repeat runs each, $(nproc) cores, $(date -u +%F)"
report "1 thread" -- --threads 1
report "2 threads" -- --threads 2
if grep -q "LPSHOOT_WITH_MPI:INTERNAL=ON" "$build/CMakeCache.txt" && command -v mpirun > /dev/null; then
  report "1 MPI rank" "${mpirun[@]}" -np 1 -- --threads 1
  report "2 MPI ranks" "${mpirun[@]}" -np 2 -- --threads 1
fi
