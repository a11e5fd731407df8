#!/usr/bin/env bash
# Issue #34's rank agreement (measured, not asserted): does the preview rank capture
# configurations by reconstruction std in the order Cycles does? Runs the sweeps
# bench/rank_agreement/six_configurations_{preview,cycles}.yaml (the paper scene, six
# configurations, the preview at its default and Cycles at 64 samples, eval). Not at 16 samples:
# Cycles' own noise at 16 changes its order of the apertures (docs/fidelity.md).
#
# COLMAP is not deterministic (one scene's std moves by 2-4 % between evaluations, as much as
# some configurations differ), so each variant is evaluated EVALS times in all (the sweep's eval
# and EVALS-1 more, kept in eval2, eval3, ...) and the ranks are those of the means.
#
# Usage: bench/rank_agreement.sh [OUT_DIR] [EVALS]
#   defaults: out/rank-agreement, 3. RIGC: the rigc binary (default ./build/rigc).
# The Cycles sweep renders 120 shots at 0.25 scale, about 2.4 minutes each on two quiet cores (5
# hours); it resumes where it stopped, so it can be run in parts.
set -euo pipefail
cd "$(dirname "$0")/.."
rigc=${RIGC:-./build/rigc}
out=${1:-out/rank-agreement}
evals=${2:-3}

# shellcheck source=bench/evaluate_again.sh
source bench/evaluate_again.sh

# Per variant: each evaluation's std, points and F-score and their means; then Spearman's rho
# between the backends' rankings of the configurations by each mean.
summarise() {
  python3 - "$@" <<'PY'
import glob, json, os, random, sys
from itertools import combinations
from statistics import mean, stdev

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

# Per configuration and backend: the evaluations' (std, points, F-score). A configuration is a
# variant's name without its backend part; the backend is the variant's.
configs = {}
print("variant\tevaluations: std (mm) / points / F\tmean std\tmean points\tmean F")
for folder in sys.argv[1:]:
    sweep = json.load(open(os.path.join(folder, "sweep.json")))
    for v in sweep["variants"]:
        evals = []
        for path in sorted(glob.glob(os.path.join(folder, v["name"], "eval*", "eval.json"))):
            e = json.load(open(path))
            evals.append((e["signed_distance_mm"]["std"], e["reconstruction"]["points"],
                          e["fscore"]["fscore"]))
        if not evals:
            print(f'{v["name"]} ({v["backend"]})\tno evaluation')
            continue
        m = tuple(mean(e[i] for e in evals) for i in range(3))
        config = v["name"].split("_backend-")[0]
        configs.setdefault(config, {})[v["backend"]] = evals
        each = ", ".join(f"{s:.4f} / {p} / {f:.3f}" for s, p, f in evals)
        print(f'{config} ({v["backend"]})\t{each}\t{m[0]:.4f}\t{m[1]:.0f}\t{m[2]:.3f}')

paired = {c: b for c, b in configs.items() if "preview" in b and "cycles" in b}
names = sorted(paired)
if len(names) >= 2:
    for i, measure in enumerate(["std", "points", "F-score"]):
        a = [mean(e[i] for e in paired[c]["preview"]) for c in names]
        b = [mean(e[i] for e in paired[c]["cycles"]) for c in names]
        print(f"Spearman rho, preview vs cycles, mean {measure} over {len(names)} configurations: "
              f"{spearman(a, b):+.3f}")
    # How much of rho COLMAP's spread decides: rho of std with one evaluation drawn at random per
    # configuration and backend, 2000 draws (seeded), as its 5th, 50th and 95th percentiles.
    draw = random.Random(1)
    draws = sorted(
        spearman([draw.choice(paired[c]["preview"])[0] for c in names],
                 [draw.choice(paired[c]["cycles"])[0] for c in names]) for _ in range(2000))
    print(f"  rho of std from single evaluations drawn at random: 5 % {draws[100]:+.3f}, "
          f"median {draws[1000]:+.3f}, 95 % {draws[1900]:+.3f}")
    # The most any predictor could reach when COLMAP's spread decides: each backend's rho of std
    # against itself, two different evaluations drawn per configuration (2000 draws, seeded).
    for backend in ("cycles", "preview"):
        if any(len(paired[c][backend]) < 2 for c in names):
            continue
        pairs = [[draw.sample(paired[c][backend], 2) for c in names] for _ in range(2000)]
        selfs = sorted(spearman([p[0][0] for p in ps], [p[1][0] for p in ps]) for ps in pairs)
        print(f"  rho of {backend}'s std against its own other evaluation: 5 % {selfs[100]:+.3f}, "
              f"median {selfs[1000]:+.3f}, 95 % {selfs[1900]:+.3f}")
    # The pairs of configurations whose std Cycles tells apart (means further apart than twice
    # the standard error of their difference, from the spread of the evaluations), and how many
    # of them the preview orders the same way.
    def std_stats(evals):
        values = [e[0] for e in evals]
        return mean(values), (stdev(values) ** 2 / len(values) if len(values) > 1 else 0.0)
    resolved = agreeing = 0
    for x, y in combinations(names, 2):
        (cx, vx), (cy, vy) = std_stats(paired[x]["cycles"]), std_stats(paired[y]["cycles"])
        if min(len(paired[x]["cycles"]), len(paired[y]["cycles"])) < 2 or \
                abs(cx - cy) <= 2 * (vx + vy) ** 0.5:
            continue
        resolved += 1
        px, py = std_stats(paired[x]["preview"])[0], std_stats(paired[y]["preview"])[0]
        same = (px - py) * (cx - cy) > 0
        agreeing += same
        print(f"  {x} vs {y}: cycles {cx:.4f} vs {cy:.4f}, preview {px:.4f} vs {py:.4f}"
              f"{'' if same else ' (opposite)'}")
    print(f"pairs of configurations Cycles orders by std beyond its evaluations' spread: "
          f"{resolved} of {len(names) * (len(names) - 1) // 2}; the preview orders {agreeing} of "
          f"them the same way")
PY
}

# Runs a sweep file into `dir` and evaluates its variants until each has `evals` evaluations.
run_sweep() {
  "$rigc" sweep "bench/rank_agreement/$1" -o "$2" || true
  evaluate_again "$2"
}

run_sweep six_configurations_preview.yaml "$out/six-preview"
run_sweep six_configurations_cycles.yaml "$out/six-cycles"
echo "== six configurations, the preview and Cycles at 64 samples, $evals evaluations a variant"
summarise "$out/six-preview" "$out/six-cycles"
