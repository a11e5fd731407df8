#!/usr/bin/env bash
# How the verbs grow with the object's triangles and the capture's shots (issue #59 item 4): the
# wall time and peak memory (the largest resident set, GNU time's %M) of `render` (the preview at
# SCALE), `coverage`, `plan` (85 % from that many candidate poses on the scene's ring) and `eval
# --reconstruction` (the render's ground-truth points measured against the mesh, aligned through
# the render's cameras: eval's own part, no COLMAP) on the paper scene, its statue at detail 4, 6,
# 8 and 9 (9680, 100820, 1012500 and 3200000 triangles) with 18 shots, and at detail 6 with 72 and
# 360, and at detail 9 with 360: what a museum-scale capture costs. Then each verb's growth
# exponent: the slope of log time (and of log memory) against log triangles at 18 shots, and
# against log shots at 100k triangles.
#
# Resumable: each measured run leaves OUT/cells/<cell>/<verb>.time, and a rerun measures only what
# is missing (delete a file to measure it again).
#
# Usage: bench/scaling.sh [OUT] [SCALE]   (defaults: out/scaling, 0.25)
set -euo pipefail
cd "$(dirname "$0")/.."
export LC_ALL=C
out=${1:-out/scaling}
scale=${2:-0.25}
rigc=./build/rigc
[ -x "$rigc" ] || { echo "scaling: build first ($rigc is missing)" >&2; exit 2; }
[[ "$scale" =~ ^[0-9]*\.?[0-9]+$ ]] || { echo "scaling: SCALE must be a number" >&2; exit 2; }
cells=("4 18" "6 18" "8 18" "9 18" "6 72" "6 360" "9 360")
verbs=(render coverage plan eval)

# The paper scene with its statue at `detail` and `shots` turntable steps a turn.
write_scene() {  # detail shots path
  python3 - "$1" "$2" "$3" <<'PY'
import sys
detail, shots, path = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
text = open("scenes/paper-turntable.yaml").read()
for old, new in [("detail: 6", "detail: %d" % detail),
                 ("steps: 18, step: 20deg", "steps: %d, step: %gdeg" % (shots, 360 / shots))]:
    assert old in text, old
    text = text.replace(old, new)
open(path, "w").write(text)
PY
}

# The render's ground-truth points (sparse/points3D.txt) as a PLY point cloud.
points_as_ply() {  # run ply
  python3 - "$1/sparse/points3D.txt" "$2" <<'PY'
import sys
points = [l.split()[1:4] for l in open(sys.argv[1]) if l.strip() and not l.startswith("#")]
with open(sys.argv[2], "w") as f:
    f.write("ply\nformat ascii 1.0\nelement vertex %d\n" % len(points))
    f.write("property float x\nproperty float y\nproperty float z\nend_header\n")
    f.writelines(" ".join(p) + "\n" for p in points)
PY
}

# Runs one verb of a cell under GNU time, unless measured already.
measure() {  # cell_dir verb shots
  local dir=$1 verb=$2 shots=$3 scene=$1/scene.yaml
  [ -s "$dir/$verb.time" ] && return 0
  local args
  case $verb in
    render) rm -rf "$dir/run"; args=(render "$scene" --scale "$scale" -o "$dir/run") ;;
    coverage) rm -rf "$dir/coverage"; args=(coverage "$scene" -o "$dir/coverage") ;;
    plan)
      args=(plan "$scene" --rings 0 --azimuth-step "$((360 / shots))deg" --target 85%
        -o "$dir/plan.yaml") ;;
    eval)
      [ -s "$dir/points.ply" ] || points_as_ply "$dir/run" "$dir/points.ply"
      rm -rf "$dir/eval"
      args=(eval "$dir/run" --reconstruction "$dir/points.ply" --cameras "$dir/run/sparse"
        -o "$dir/eval") ;;
  esac
  echo "scaling: $(basename "$dir") $verb" >&2
  if ! /usr/bin/time -f "%e %M" -o "$dir/$verb.time.tmp" "$rigc" "${args[@]}" >"$dir/$verb.log" 2>&1; then
    echo "scaling: $(basename "$dir") $verb failed (log: $dir/$verb.log)" >&2
    rm -f "$dir/$verb.time.tmp"
    return 1
  fi
  mv "$dir/$verb.time.tmp" "$dir/$verb.time"
}

status=0
for cell in "${cells[@]}"; do
  read -r detail shots <<<"$cell"
  dir=$out/cells/detail${detail}_${shots}shots
  mkdir -p "$dir"
  [ -s "$dir/scene.yaml" ] || write_scene "$detail" "$shots" "$dir/scene.yaml"
  for verb in "${verbs[@]}"; do measure "$dir" "$verb" "$shots" || status=1; done
done

python3 - "$out" "${verbs[@]}" <<'PY'
import math, os, sys
out, verbs = sys.argv[1], sys.argv[2:]
triangles = {4: 9680, 6: 100820, 8: 1012500, 9: 3200000}
rows = {}
for name in sorted(os.listdir(os.path.join(out, "cells"))):
    detail, shots = name.replace("detail", "").replace("shots", "").split("_")
    for verb in verbs:
        path = os.path.join(out, "cells", name, verb + ".time")
        if os.path.exists(path):
            wall, rss_kb = open(path).read().split()[-2:]
            rows[(int(detail), int(shots), verb)] = (float(wall), int(rss_kb) / 1024)
print("| triangles | shots | " + " | ".join("%s s, MB" % v for v in verbs) + " |")
print("|---:|---:|" + "---:|" * len(verbs))
for d, s in sorted({(d, s) for d, s, _ in rows}):
    cells = ["%.1f, %.0f" % rows[(d, s, v)] if (d, s, v) in rows else "-" for v in verbs]
    print("| %d | %d | %s |" % (triangles[d], s, " | ".join(cells)))
def slope(points):  # least-squares slope of log y against log x
    if len(points) < 2:
        return None
    xs = [math.log(x) for x, _ in points]
    ys = [math.log(max(y, 1e-3)) for _, y in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
print("\n| verb | time ~ triangles^k | memory ~ triangles^k | time ~ shots^k | memory ~ shots^k |")
print("|---|---:|---:|---:|---:|")
for v in verbs:
    by_tris = [(triangles[d], rows[(d, 18, v)]) for d in triangles if (d, 18, v) in rows]
    by_shots = [(s, rows[(6, s, v)]) for s in (18, 72, 360) if (6, s, v) in rows]
    k = [slope([(x, r[i]) for x, r in series]) for series in (by_tris, by_shots) for i in (0, 1)]
    print("| %s | %s |" % (v, " | ".join("-" if x is None else "%.2f" % x for x in k)))
PY
exit $status
