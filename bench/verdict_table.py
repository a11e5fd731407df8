#!/usr/bin/env python3
"""The verdict benchmark's table (bench/verdict/README.md), from the sweep folders bench/verdict.sh
ran: per configuration each backend's verdict, their agreement, the pairs Cycles separates
beyond its own spread and how many the preview orders alike, and check's warnings against the
verdicts.

Usage: verdict_table.py EVALS SCENE=SWEEP_DIR=BASE_SCENE ...
"""
import glob, json, os, sys
from itertools import combinations
from statistics import mean

evals_wanted = int(sys.argv[1])
# A verdict: pass (>= 90 % of the shots registered and an F-score >= 80 % of the same backend's
# passing baseline), failed (under half the shots registered, or no model), else degraded.
# Without the backend's baseline a registered configuration has no verdict yet.
def verdict(registered, shots, fscore, baseline_fscore):
    if shots == 0 or registered < 0.5 * shots:
        return "failed"
    if baseline_fscore is None:
        return "no baseline yet"
    if registered >= 0.9 * shots and fscore >= 0.8 * baseline_fscore:
        return "pass"
    return "degraded"

# Each evaluation's (registered, shots, F-score); a reconstruction that failed registers none.
def evaluations(variant_dir):
    shots = len(glob.glob(os.path.join(variant_dir, "images", "*")))
    found = []
    for path in sorted(glob.glob(os.path.join(variant_dir, "eval*", "eval.json"))):
        e = json.load(open(path))
        rec = e.get("reconstruction", {})
        found.append((rec.get("registered_images", 0) if rec.get("status") == "ok" else 0,
                      shots, e.get("fscore", {}).get("fscore", 0.0)))
    return found

def changed_lines(base_text, variant_text):
    base = base_text.splitlines()
    return {i + 1 for i, line in enumerate(variant_text.splitlines())
            if i >= len(base) or line != base[i]}

def warnings(variant_dir):
    try:
        report = json.load(open(os.path.join(variant_dir, "check.json")))
    except (OSError, ValueError):
        return None
    return [d for d in report.get("diagnostics", []) if d.get("severity") == "warning"]

rows = {}  # (scene, configuration) -> {backend: [(registered, shots, F)], "check": [...], ...}
for entry in sys.argv[2:]:
    scene, folder, base_scene = entry.split("=")
    if not os.path.exists(os.path.join(folder, "sweep.json")):
        continue  # the sweep did not start (its error is above)
    sweep = json.load(open(os.path.join(folder, "sweep.json")))
    base_text = open(base_scene).read()
    for v in sweep["variants"]:
        config = v["name"].split("_backend-")[0]
        row = rows.setdefault((scene, config), {})
        vdir = os.path.join(folder, v["name"])
        row[v["backend"]] = evaluations(vdir)
        found = warnings(vdir)
        if found is not None and os.path.exists(os.path.join(vdir, "scene.yaml")):
            lines = changed_lines(base_text, open(os.path.join(vdir, "scene.yaml")).read())
            row["check"] = [(d.get("line"), d.get("line") in lines, d.get("message", ""))
                            for d in found]

baseline = {}
for (scene, config), row in rows.items():
    if config == "steps-18_step-20deg":
        for backend in ("preview", "cycles"):
            if row.get(backend):
                baseline[(scene, backend)] = mean(e[2] for e in row[backend])

def summary(scene, row, backend):
    found = row.get(backend) or []
    if not found:
        return None
    reg = mean(e[0] for e in found)
    shots = max(e[1] for e in found)
    f = mean(e[2] for e in found)
    return {"reg": reg, "shots": shots, "f": f, "n": len(found), "each": [e[2] for e in found],
            "verdict": verdict(reg, shots, f, baseline.get((scene, backend)))}

print("| scene | configuration | preview: registered, F (evals) | verdict | Cycles: registered, "
      "F (evals) | verdict | check warnings (line: at a changed line?) |")
print("|---|---|---|---|---|---|---|")
agree = compared = 0
table = []
for (scene, config), row in sorted(rows.items()):
    p, c = summary(scene, row, "preview"), summary(scene, row, "cycles")
    cell = lambda s: f'{s["reg"]:.1f}/{s["shots"]}, {s["f"]:.3f} ({s["n"]})' if s else "-"
    check = row.get("check")
    check_text = "-" if check is None else (
        "; ".join(f'{line}: {"yes" if at else "no"} {msg[:60]}' for line, at, msg in check)
        or "none")
    print(f'| {scene} | {config} | {cell(p)} | {p["verdict"] if p else "-"} | {cell(c)} | '
          f'{c["verdict"] if c else "-"} | {check_text} |')
    table.append((scene, config, p, c, check))
    if p and c:
        compared += 1
        agree += p["verdict"] == c["verdict"]

print(f"\nverdict agreement: {agree} of {compared} configurations with both backends")
for scene in sorted({t[0] for t in table}):
    # Pairs Cycles separates by F-score beyond its own evaluations' spread (the ranges do not
    # overlap), and how many the preview orders the same way.
    done = [(cfg, p, c) for s, cfg, p, c, _ in table if s == scene and p and c and c["n"] >= 2]
    resolved = same = 0
    for (x, px, cx), (y, py, cy) in combinations(done, 2):
        if min(cx["each"]) > max(cy["each"]) or min(cy["each"]) > max(cx["each"]):
            resolved += 1
            same += (px["f"] - py["f"]) * (cx["f"] - cy["f"]) > 0
    print(f"{scene}: pairs Cycles separates by F beyond its spread: {resolved}; the preview "
          f"orders {same} of them the same way")
# check's recall: configurations that the reference (Cycles, else the preview while Cycles is
# pending) fails or degrades with a warning at a changed line; precision: passing ones with any.
for source in ("cycles", "preview"):
    bad = [(s, cfg, chk) for s, cfg, p, c, chk in table
           if (c if source == "cycles" else p) and (c if source == "cycles" else p)["verdict"] != "pass"]
    good = [(s, cfg, chk) for s, cfg, p, c, chk in table
            if (c if source == "cycles" else p) and (c if source == "cycles" else p)["verdict"] == "pass"]
    named = sum(1 for _, _, chk in bad if chk and any(at for _, at, _ in chk))
    noisy = sum(1 for _, _, chk in good if chk)
    print(f"check against {source}'s verdicts: {named} of {len(bad)} failing or degraded "
          f"configurations warned at a changed line; {noisy} of {len(good)} passing ones warned")
missing = [f"{s}/{cfg}" for s, cfg, p, c, _ in table
           if not p or not c or p["n"] < evals_wanted or c["n"] < evals_wanted]
print(f"\nconfigurations still short of {evals_wanted} evaluations on a backend: {len(missing)}")
