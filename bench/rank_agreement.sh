#!/usr/bin/env bash
# Issue #34's rank agreement (measured, not asserted): does the preview rank capture
# configurations by reconstruction std in the order Cycles does? Runs the sweep
# bench/rank_agreement/six_configurations.yaml (the paper scene, six configurations, preview and
# Cycles at 16 samples, eval), then two of them with Cycles at 64 samples
# (two_at_64_samples.yaml) to show that 16 samples do not change Cycles' own order.
#
# Usage: bench/rank_agreement.sh [OUT_DIR] [WHICH]
#   defaults: out/rank-agreement, "six 64". WHICH: six and/or 64.
#   RIGC: the rigc binary (default ./build/rigc).
# The six-configuration sweep renders 120 Cycles shots at 0.25 scale and runs COLMAP 12 times:
# about two hours on two cores.
set -euo pipefail
cd "$(dirname "$0")/.."
rigc=${RIGC:-./build/rigc}
out=${1:-out/rank-agreement}
which=${2:-six 64}

# Variant, backend and std (mm) from a sweep's results.csv.
stds() {
  python3 - "$1" <<'PY'
import csv, sys
for row in csv.DictReader(open(sys.argv[1])):
    std = row.get("std_mm", "")
    print(f'{row["variant"]}\t{row["status"]}\t{std}')
PY
}

for w in $which; do
  case $w in
    six) sweep=bench/rank_agreement/six_configurations.yaml dir=$out/six ;;
    64) sweep=bench/rank_agreement/two_at_64_samples.yaml dir=$out/cycles-64 ;;
    *) echo "rank_agreement.sh: unknown part $w (six, 64)" >&2; exit 1 ;;
  esac
  "$rigc" sweep "$sweep" -o "$dir" || true
  echo "== $sweep"
  stds "$dir/results.csv"
  sed -n '/## Rank agreement/,$p' "$dir/results.md"
done
