#!/usr/bin/env bash
# The digital twin of the real temple (docs/twin.md) against the real photos: does the twin's
# preview predict what COLMAP does with the photos? Each set is evaluated EVALS times (COLMAP is
# bimodal on these photos: docs/real-photos.md), with the same reference cameras and matcher.
#
# Usage: bench/twin_table.sh [OUT_DIR] [EVALS] [RING_VIEWS]   (defaults: out/twin-table, 3, 32)
# Prints the time of `rigc twin` and of one eval, then a row per set: registered, points (3+
# images), AUC at 5 degrees, each as min / mean / max over the evaluations; then the twin's
# silhouette IoU against the photos' masks (lowest, median).
set -euo pipefail
cd "$(dirname "$0")/.."
rigc=./build/rigc
out=${1:-out/twin-table}
evals=${2:-3}
ring=${3:-32}
temple=tests/real/templeSparseRing
mkdir -p "$out"

t0=$(date +%s.%N)
"$rigc" twin "$temple" --reference-cameras "$temple/templeSR_par.txt" -o "$out/twin" \
  --ring-views "$ring" -q
t1=$(date +%s.%N)
"$rigc" render "$out/twin/ring_$ring.yaml" --backend preview -o "$out/ring" >"$out/ring.log" 2>&1

# evaluate NAME PHOTOS REFERENCE: EVALS evaluations into OUT/NAME/eval_K (kept: a rerun reuses them).
evaluate() {
  local name=$1 photos=$2 reference=$3
  for k in $(seq 1 "$evals"); do
    local dir="$out/$name/eval_$k"
    [[ -f $dir/eval.json ]] && continue
    "$rigc" eval --photos "$photos" --reference-cameras "$reference" --matcher exhaustive \
      --allow-partial -o "$dir" >"$out/$name.eval_$k.log" 2>&1 || true
  done
}
t2=$(date +%s.%N)
evaluate real "$temple" "$temple/templeSR_par.txt"
t3=$(date +%s.%N)
evaluate twin "$out/twin/render/images" "$out/twin/render/sparse"
evaluate "ring$ring" "$out/ring/images" "$out/ring/sparse"

/usr/bin/python3 - "$out" "$evals" "$ring" "$t0" "$t1" "$t2" "$t3" <<'PY'
import json, os, statistics, sys
out, evals, ring = sys.argv[1], int(sys.argv[2]), sys.argv[3]
t0, t1, t2, t3 = map(float, sys.argv[4:8])
print(f"rigc twin (hull, colours, 3 x 4 calibration renders, 16 renders): {t1 - t0:.1f} s; "
      f"{evals} evaluations of the 16 real photos: {t3 - t2:.1f} s")
print()
print("| set | registered (min / mean / max) | points, 3+ images | AUC @ 5 deg (%) |")
print("|---|---|---|---|")
for name, label in (("real", "real photos, 16"), ("twin", "twin, 16 views (preview)"),
                    (f"ring{ring}", f"twin, {ring} views on the ring (preview)")):
    reg, pts, auc = [], [], []
    for k in range(1, evals + 1):
        path = os.path.join(out, name, f"eval_{k}", "eval.json")
        if not os.path.exists(path):
            continue
        report = json.load(open(path))
        rec = report.get("reconstruction", {})
        reg.append(rec.get("registered_images", 0))
        pts.append(rec.get("points", 0))
        auc.append(report.get("cameras", {}).get("relative_pose_auc_percent", {}).get("5", 0.0))
    if not reg:
        print(f"| {label} | - | - | - |")
        continue
    fmt = lambda v, f: f"{f(min(v))} / {f(statistics.mean(v))} / {f(max(v))}"
    print(f"| {label} | {fmt(reg, lambda x: f'{x:.3g}')} | {fmt(pts, lambda x: f'{x:.0f}')} | "
          f"{fmt(auc, lambda x: f'{x:.1f}')} |")
twin = json.load(open(os.path.join(out, "twin", "twin.json")))
c = twin["comparison"]
print()
print(f"silhouette IoU, twin against the photos' masks: lowest {c['min_silhouette_iou']:.3f}, "
      f"median {c['median_silhouette_iou']:.3f}")
PY
