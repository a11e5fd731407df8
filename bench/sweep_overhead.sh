#!/usr/bin/env bash
# rigc sweep's own cost: 12 preview variants of the paper scene at 0.25 scale, coverage only,
#   1. each variant as a single `rigc render --scale 0.25` + `rigc coverage` (the sum of 12 runs),
#   2. the same 12 through `rigc sweep` (local executor),
#   3. through `rigc sweep --executor slurm --cpus-per-task 2` (one task at a time, as locally),
# and prints the sweep's overhead against the singles and the Slurm executor's per task.
# Needs a Slurm cluster for 3 (bash scripts/slurm_cluster.sh start; SLURM_CONF set), else skips it.
# Usage: bash bench/sweep_overhead.sh [RIGC] [WORK_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
rigc=$(realpath "${1:-build/rigc}")
work=${2:-$(mktemp -d /tmp/rigc-sweep-bench.XXXXXX)}
mkdir -p "$work"
cat >"$work/bench.yaml" <<YAML
rigc-sweep: 1
scene: $PWD/scenes/paper-turntable.yaml
vary:
  camera.exposure.aperture: [f/4, f/8, f/13, f/22]
  shots[0].turntable.steps: [12, 18, 36]
  shots[0].turntable.step: [30deg, 20deg, 10deg]
zip: ["shots[0].turntable.steps", "shots[0].turntable.step"]
scale: 0.25
measure: [coverage]
YAML
now() { date +%s.%N; }

# The variants' scene files, from a sweep that stops before running (its folders are written
# first); a status call writes them without running anything.
"$rigc" sweep "$work/bench.yaml" -o "$work/scenes" --status >/dev/null
singles=0
for scene in "$work"/scenes/*/scene.yaml; do
  name=$(basename "$(dirname "$scene")")
  start=$(now)
  "$rigc" render "$scene" --backend preview --scale 0.25 -o "$work/single/$name" >/dev/null 2>&1
  "$rigc" coverage "$scene" -o "$work/single/$name/coverage" >/dev/null 2>&1
  singles=$(echo "$singles + $(now) - $start" | bc)
done

start=$(now)
"$rigc" sweep "$work/bench.yaml" -o "$work/local" >/dev/null 2>&1
local_s=$(echo "$(now) - $start" | bc)

printf 'sum of 12 single runs  %7.1f s\n' "$singles"
printf 'rigc sweep (local)     %7.1f s   (%+.1f %%)\n' "$local_s" \
  "$(echo "($local_s - $singles) * 100 / $singles" | bc -l)"
if sinfo -h >/dev/null 2>&1; then
  start=$(now)
  "$rigc" sweep "$work/bench.yaml" -o "$work/slurm" --executor slurm --cpus-per-task 2 \
    >/dev/null 2>&1
  slurm_s=$(echo "$(now) - $start" | bc)
  cmp -s "$work/local/results.csv" "$work/slurm/results.csv" && same=same || same=DIFFERENT
  printf 'rigc sweep (slurm)     %7.1f s   (%+.2f s per task against local; results.csv %s)\n' \
    "$slurm_s" "$(echo "($slurm_s - $local_s) / 12" | bc -l)" "$same"
fi
echo "work folder: $work"
