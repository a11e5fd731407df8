#!/usr/bin/env bash
# Issue #55's verdict benchmark (measured, not asserted; bench/verdict/README.md): does the
# preview fail where the converged Cycles reference fails, and does `rigc check` say so at the
# responsible line? Runs every sweep file bench/verdict/SCENE-*.yaml (the preview and Cycles at
# --samples auto, coverage and eval), evaluates each variant EVALS times in all (eval, eval2, ...:
# COLMAP is not deterministic), runs `rigc check --json` on each variant's scene, and prints the
# verdict table and the targets' figures. Everything resumes where it stopped.
#
# Usage: bench/verdict.sh [OUT_DIR] [EVALS] [SCENES] [BACKENDS]
#   defaults: out/verdict, 3, "paper spot", "preview cycles" (BACKENDS: which variants to run
#   now, e.g. "preview" for the fast half; the table shows whatever has results).
#   RIGC: the rigc binary (default ./build/rigc); CALIBRATION: build/bench/calibration_table. SWEEPS: the folder of sweep files and scenes
#   (default bench/verdict; a copy at another scale for the scale study).
set -euo pipefail
cd "$(dirname "$0")/.."
rigc=${RIGC:-./build/rigc}
calibration=${CALIBRATION:-./build/bench/calibration_table}
rigc_binary=$(command -v "$rigc")
out=${1:-out/verdict}
evals=${2:-3}
scenes=${3:-paper spot}
backends=${4:-preview cycles}
sweeps=${SWEEPS:-bench/verdict}

# shellcheck source=bench/evaluate_again.sh
source bench/evaluate_again.sh

# `rigc check --json` of each variant's scene at the sweep's render scale (the camera whose photos
# the variants are), once per scene text and rigc.
check_variants() {
  local dir=$1 variant scale
  scale=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["scale"])' \
    "$dir/sweep.json")
  for variant in "$dir"/*/; do
    [[ -f $variant/scene.yaml ]] || continue
    # Kept while newer than the scene and the rigc that wrote it (advice changes with rigc).
    [[ -f $variant/check.json && ! $variant/scene.yaml -nt $variant/check.json &&
      ! $rigc_binary -nt $variant/check.json ]] && continue
    "$rigc" check --json --scale "$scale" "$variant/scene.yaml" >"$variant/check.json.tmp" \
      2>/dev/null || true
    mv "$variant/check.json.tmp" "$variant/check.json"
  done
}

folders=()
for scene in $scenes; do
  for file in "$sweeps/$scene"-*.yaml; do
    dir=$out/$(basename "$file" .yaml)
    folders+=("$scene=$dir=$sweeps/$scene.yaml")
    # A variant that fails is reported by the sweep and shown as failed in the table.
    "$rigc" sweep "$file" -o "$dir" --backend "${backends// /,}" || true
    evaluate_again "$dir"
    check_variants "$dir"
  done
done

python3 bench/verdict_table.py "$evals" "${folders[@]}"

# Coverage calibration: each evaluated variant's prediction against its reconstruction, in 20 mm
# patches (a sparse cloud confirms no single triangle; bench/calibration_table.cpp).
evaluated=()
for entry in "${folders[@]}"; do
  dir=${entry#*=}
  dir=${dir%%=*}
  for variant in "$dir"/*/; do
    [[ -f $variant/eval/cloud_signed_distance.ply ]] && evaluated+=("$variant")
  done
done
if ((${#evaluated[@]})); then
  echo
  "$calibration" --patch 20 "${evaluated[@]}"
fi
