#!/usr/bin/env bash
# Real photos (issue #39 target, measured, not asserted): the paper scene's 18 renders copied as a
# photographer's card would hold them (plain JPEGs: no sparse/, masks/ or manifest.json) must
# register 18/18 with a signed-distance std within 1.15x of the run folder's evaluation of the
# same images; the same with the EXIF stripped and `--camera canon-6d,50mm` given.
#
# Usage: bench/photos_table.sh [OUT_DIR] [SCALE] [BACKEND]   (defaults: out/photos-table, 0.25,
#        preview; the Cycles renders take about 20 minutes at 0.25 on 2 cores)
# Prints one table row per input: registered images, points, signed distance mean ± std, the
# std's ratio to the run folder's, F-score at 1 mm, COLMAP's wall time.
set -euo pipefail
cd "$(dirname "$0")/.."
rigc=./build/rigc
out=${1:-out/photos-table}
scale=${2:-0.25}
backend=${3:-preview}
scene=scenes/paper-turntable.yaml
mkdir -p "$out"
if ! "$rigc" render "$scene" --backend "$backend" --scale "$scale" -o "$out/run" >"$out/render.log" 2>&1; then
  cat "$out/render.log" >&2
  exit 2
fi

# The JPEGs as they are, and without their metadata segments (APP1..APP15: EXIF, XMP, IPTC).
rm -rf "$out/photos" "$out/stripped"
mkdir -p "$out/photos" "$out/stripped"
cp "$out/run"/images/*.jpg "$out/photos/"
python3 - "$out/photos" "$out/stripped" <<'PY'
import os, struct, sys
src, dst = sys.argv[1], sys.argv[2]
for name in sorted(os.listdir(src)):
    data = open(os.path.join(src, name), "rb").read()
    out, i = bytearray(data[:2]), 2
    while i + 4 <= len(data) and data[i] == 0xFF and data[i + 1] != 0xDA:
        length = struct.unpack(">H", data[i + 2:i + 4])[0]
        if not 0xE1 <= data[i + 1] <= 0xEF:
            out += data[i:i + 2 + length]
        i += 2 + length
    open(os.path.join(dst, name), "wb").write(bytes(out + data[i:]))
PY

evaluate() {  # name, args...
  local name=$1
  shift
  local code=0
  "$rigc" eval "$@" -o "$out/eval_$name" >"$out/eval_$name.log" 2>&1 || code=$?
  echo "$code" >"$out/eval_$name.exit"
}
evaluate run "$out/run"
evaluate photos --photos "$out/photos" --scene "$scene"
evaluate stripped --photos "$out/stripped" --scene "$scene" --camera canon-6d,50mm

python3 - "$out" "$scale" "$backend" <<'PY'
import json, os, sys
out, scale, backend = sys.argv[1:4]
def row(name):
    path = os.path.join(out, "eval_" + name, "eval.json")
    code = open(os.path.join(out, "eval_%s.exit" % name)).read().strip()
    if not os.path.exists(path):
        return None, code
    return json.load(open(path)), code
run, _ = row("run")
run_std = run["signed_distance_mm"]["std"] if run and "signed_distance_mm" in run else None
print("%s renders at scale %s" % (backend, scale))
print("| input | exit | registered | points | signed distance mean ± std (mm) | std / run's | F (1 mm) | matching | COLMAP (s) |")
print("|---|---|---|---|---|---|---|---|---|")
for name, label in (("run", "run folder"), ("photos", "photos, EXIF"),
                    ("stripped", "photos, EXIF stripped, --camera canon-6d,50mm")):
    r, code = row(name)
    if not r or "signed_distance_mm" not in r:
        print("| %s | %s | failed | | | | | | |" % (label, code))
        continue
    d, rec = r["signed_distance_mm"], r["reconstruction"]
    ratio = "%.2f" % (d["std"] / run_std) if run_std else ""
    print("| %s | %s | %d/%d | %d | %+.3f ± %.3f | %s | %.3f | %s | %.1f |" % (
        label, code, rec["registered_images"], rec["images"], rec["points"], d["mean"], d["std"],
        ratio, r["fscore"]["fscore"] if "fscore" in r else float("nan"),
        r["colmap"]["matching"].get("matcher", "?"), r["colmap"]["seconds"]))
PY
