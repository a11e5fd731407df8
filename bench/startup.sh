#!/usr/bin/env bash
# Start-up and check speed (issue #59 targets, measured, not asserted): `rigc --version` at most
# 20 ms and `rigc check` of the paper scene at most 0.15 s, each the mean of RUNS runs under
# `perf stat -r` (wall time, and the CPU the process used), beside rigc-all doing the same.
#
# Usage: bench/startup.sh [RUNS]   (default 20)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-20}
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "startup: RUNS must be a positive integer" >&2; exit 2; }
for binary in build/rigc build/rigc-all; do
  [ -x "$binary" ] || { echo "startup: build first ($binary is missing)" >&2; exit 2; }
done
command -v perf >/dev/null || { echo "startup: perf is missing (apt install linux-perf)" >&2; exit 2; }
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-44s %10s %10s %10s\n' command "wall ms" "cpu ms" libraries
measure() {  # binary, then its arguments
  local stats wall cpu libraries start end
  stats=$(perf stat -x, -r "$runs" -e task-clock "$@" 2>&1 >/dev/null | grep task-clock || true)
  cpu=$(cut -d, -f1 <<<"$stats")
  start=$(date +%s%N)
  for ((k = 0; k < runs; ++k)); do "$@" >/dev/null 2>&1 || true; done
  end=$(date +%s%N)
  wall=$(( (end - start) / runs / 1000 ))
  libraries=$(ldd "$1" | wc -l)
  printf '%-44s %10.1f %10.1f %10d\n' "$(basename "$1") ${*:2}" "$(awk -v us="$wall" 'BEGIN { print us / 1000 }')" \
    "$cpu" "$libraries"
}
measure build/rigc --version
measure build/rigc-all --version
measure build/rigc check scenes/paper-turntable.yaml
measure build/rigc-all check scenes/paper-turntable.yaml
