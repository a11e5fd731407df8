#!/usr/bin/env bash
# Issue #34's rank agreement (measured, not asserted): does the preview rank capture
# configurations by reconstruction std in the order Cycles does? Runs the sweep
# bench/rank_agreement/six_configurations.yaml (the paper scene, six configurations, preview and
# Cycles at 16 samples, eval), then two of them with Cycles at 64 samples
# (two_at_64_samples.yaml) to show that 16 samples do not change Cycles' own order.
#
# COLMAP is not deterministic (one scene's std moves by 2-4 % between evaluations, as much as
# some configurations differ), so each variant is evaluated EVALS times in all (the sweep's eval
# and EVALS-1 more, kept in eval2, eval3, ...) and the ranks are those of the means.
#
# Usage: bench/rank_agreement.sh [OUT_DIR] [WHICH] [EVALS]
#   defaults: out/rank-agreement, "six 64", 3. WHICH: six and/or 64.
#   RIGC: the rigc binary (default ./build/rigc).
# The six-configuration sweep renders 120 Cycles shots at 0.25 scale and runs COLMAP 12 times:
# about two hours on two cores.
set -euo pipefail
cd "$(dirname "$0")/.."
rigc=${RIGC:-./build/rigc}
out=${1:-out/rank-agreement}
which=${2:-six 64}
evals=${3:-3}

# Evaluates every variant of a sweep folder until it has `evals` evaluations (eval, eval2, ...).
evaluate_again() {
  local dir=$1 variant k
  for variant in "$dir"/*/; do
    [[ -f $variant/eval/eval.json ]] || continue
    for ((k = 2; k <= evals; k++)); do
      # Kept while it is newer than the render (a rerun sweep may have rendered again).
      [[ -f $variant/eval$k/eval.json && ! $variant/manifest.json -nt $variant/eval$k/eval.json ]] &&
        continue
      "$rigc" eval "$variant" -o "$variant/eval$k" >"$variant/eval$k.log" 2>&1 || true
    done
  done
}

# Per variant: each evaluation's std, points and F-score and their means; then Spearman's rho
# between the backends' rankings of the configurations by each mean.
summarise() {
  python3 - "$1" <<'PY'
import glob, json, os, sys
from statistics import mean

def ranks(values):
    order = sorted(range(len(values)), key=lambda i: values[i])
    r = [0.0] * len(values)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and values[order[j + 1]] == values[order[i]]:
            j += 1
        for k in range(i, j + 1):
            r[order[k]] = (i + j) / 2 + 1
        i = j + 1
    return r

def spearman(a, b):
    ra, rb = ranks(a), ranks(b)
    ma, mb = mean(ra), mean(rb)
    cov = sum((x - ma) * (y - mb) for x, y in zip(ra, rb))
    va = sum((x - ma) ** 2 for x in ra) ** 0.5
    vb = sum((y - mb) ** 2 for y in rb) ** 0.5
    return cov / (va * vb) if va and vb else float("nan")

sweep = json.load(open(os.path.join(sys.argv[1], "sweep.json")))
rows = {}
print("variant\tevaluations: std (mm) / points / F\tmean std\tmean points\tmean F")
for v in sweep["variants"]:
    folder = os.path.join(sys.argv[1], v["name"])
    evals = []
    for path in sorted(glob.glob(os.path.join(folder, "eval*", "eval.json"))):
        e = json.load(open(path))
        evals.append((e["signed_distance_mm"]["std"], e["reconstruction"]["points"],
                      e["fscore"]["fscore"]))
    if not evals:
        print(f'{v["name"]}\tno evaluation')
        continue
    m = tuple(mean(e[i] for e in evals) for i in range(3))
    rows[v["name"]] = m
    each = ", ".join(f"{s:.4f} / {p} / {f:.3f}" for s, p, f in evals)
    print(f'{v["name"]}\t{each}\t{m[0]:.4f}\t{m[1]:.0f}\t{m[2]:.3f}')

# Configurations: the variant names without their backend part.
configs = {}
for name, m in rows.items():
    config, _, backend = name.rpartition("_backend-")
    if config:
        configs.setdefault(config, {})[backend] = m
paired = {c: b for c, b in configs.items() if "preview" in b and "cycles" in b}
if len(paired) >= 2:
    names = sorted(paired)
    for i, measure in enumerate(["std", "points", "F-score"]):
        a = [paired[c]["preview"][i] for c in names]
        b = [paired[c]["cycles"][i] for c in names]
        print(f"Spearman rho, preview vs cycles, mean {measure} over {len(names)} configurations: "
              f"{spearman(a, b):+.3f}")
PY
}

for w in $which; do
  case $w in
    six) sweep=bench/rank_agreement/six_configurations.yaml dir=$out/six ;;
    64) sweep=bench/rank_agreement/two_at_64_samples.yaml dir=$out/cycles-64 ;;
    *) echo "rank_agreement.sh: unknown part $w (six, 64)" >&2; exit 1 ;;
  esac
  "$rigc" sweep "$sweep" -o "$dir" || true
  evaluate_again "$dir"
  echo "== $sweep, $evals evaluations a variant"
  summarise "$dir"
done
