#!/usr/bin/env bash
# Renders the example scenes with the preview at 0.25 scale, runs coverage, emits the POV-Ray and
# Cycles scripts, and prints the SHA-256 of every output a refactoring must leave unchanged
# (images, masks, sparse/, transforms.json, coverage.json and pictures, emitted scripts).
# Manifests and logs hold timings, so they are left out. coverage.json's sums come from parallel
# reductions whose last digit varies from run to run: its numbers are hashed at 10 significant
# digits.
#
#   bash scripts/golden_outputs.sh [RIGC_BINARY] [OUT_DIR] > hashes.txt
#   diff before.txt after.txt
set -euo pipefail
cd "$(dirname "$0")/.."
rigc=$(realpath "${1:-build/rigc}")
out=${2:-build/golden}
rm -rf -- "$out"
mkdir -p -- "$out"
for scene in scenes/paper-turntable.yaml scenes/multi-ring.yaml; do
  name=$(basename "$scene" .yaml)
  "$rigc" render "$scene" --backend preview --scale 0.25 -o "$out/$name/preview" >/dev/null 2>&1
  "$rigc" coverage "$scene" -o "$out/$name/coverage" >/dev/null
  "$rigc" compile "$scene" --target povray --scale 0.25 -o "$out/$name/povray" >/dev/null
  "$rigc" compile "$scene" --target cycles --scale 0.25 -o "$out/$name/cycles" >/dev/null
done
cd -- "$out"
find . -type f ! -name manifest.json ! -name '*.log' ! -name '.rigc.lock' ! -name coverage.json \
  -print0 | LC_ALL=C sort -z | xargs -0 sha256sum
for json in */coverage/coverage.json; do
  python3 -c 'import json, sys
def rounded(v):
    if isinstance(v, float): return float(f"{v:.10g}")
    if isinstance(v, list): return [rounded(x) for x in v]
    if isinstance(v, dict): return {k: rounded(x) for k, x in v.items()}
    return v
print(json.dumps(rounded(json.load(open(sys.argv[1]))), sort_keys=True))' "$json" |
    sha256sum | sed "s|-\$|./$json (10 digits)|"
done
