#!/usr/bin/env bash
# Writes docs/guide.md, the guide from a model file to a capture plan, by running every command
# it shows: each command's real output and pictures go in, so the guide cannot go stale. The
# test EvalEndToEnd.TheGuideRuns runs it into a folder of its own.
#
# Usage: bash scripts/guide.sh [OUT_DIR] [GUIDE]   (defaults: out/guide, docs/guide.md; its
# pictures go beside GUIDE in guide/). Needs ./build/rigc, COLMAP and Blender; about 5 minutes,
# 3 of them Cycles' (GUIDE_REFERENCE= compares the preview alone, as the test does; POV-Ray at
# this scale took 5 minutes). RIGC names the binary (default ./build/rigc).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/guide}
guide=${2:-docs/guide.md}
pictures=$(dirname "$guide")/guide
rigc=${RIGC:-./build/rigc}
reference=${GUIDE_REFERENCE-cycles}  # set empty: the preview alone
rm -rf "$out"
mkdir -p "$out" "$pictures"
doc=$(mktemp "$guide.XXXXXX")
trap 'rm -f "$doc"' EXIT

say() { printf '%s\n' "$@" >>"$doc"; }
# show CMD...: runs it, and writes the command and the last lines of its output as a console block
# (EXIT_ALLOWED: an exit code besides 0 that is the command's answer, as plan's 1).
show() {
  local command="$*"
  printf '```console\n$ rigc %s\n' "${command#"$rigc "}" | sed -e "s|$out/|out/guide/|g" >>"$doc"
  local log="$out/last.log"
  local code=0
  "$@" >"$log" 2>&1 || code=$?
  if ((code != 0 && code != ${EXIT_ALLOWED:-0})); then
    cat "$log" >&2
    echo "guide: '$*' failed" >&2
    exit 1
  fi
  sed -e "s|$PWD/||g" -e "s|$out/|out/guide/|g" "$log" | tail -n "${LINES_SHOWN:-20}" >>"$doc"
  say '```' ''
}
# picture NAME FILES...: a mosaic of FILES (two a row, 480 px wide each) into the pictures folder.
picture() {
  local name=$1
  shift
  oiiotool "$@" --mosaic 2x$(((${#} + 1) / 2)) --resize 960x0 -o "$pictures/$name" >/dev/null
}

spot=scenes/assets/spot/spot.obj
scene=$out/spot.yaml
say '# From a model file to a capture plan' '' \
  'A walk through RigC as a user takes it, on Spot (`scenes/assets/spot`, a scanned cow with its' \
  'photographed texture). Every output below is what the commands printed when' \
  '`bash scripts/guide.sh` last wrote this page; the pictures are theirs too.' ''

say '## 1. A scene for the object' '' \
  '`rigc new` writes a commented scene: where the camera stands, the aperture, the lights, the' \
  'exposure `check` settles and the planner'"'"'s shots, each choice explained at its line.' ''
show "$rigc" new "$spot" --height 20cm -o "$scene"
say 'The camera section it wrote:' '' '```yaml'
sed -n '/^camera:/,/^shots:/p' "$scene" | sed '$d' >>"$doc"
say '```' ''

say '## 2. Check it' '' \
  '`rigc check` compiles the scene and gives capture advice at the responsible line; this one is' \
  'clean.' ''
show "$rigc" check "$scene"

say '## 3. Its photos, through the camera model' ''
show "$rigc" render "$scene" --backend preview --scale 0.25 -o "$out/preview"
picture guide-preview.jpg "$out"/preview/images/shot_00{0,3,6,9}.jpg
say '![four of the preview'"'"'s photos](guide/guide-preview.jpg)' ''

say '## 4. What SfM can use' '' \
  'White faces no shot sees, red faces one usable view, green two or more.' ''
show "$rigc" coverage "$scene" -o "$out/coverage"
picture guide-coverage.jpg "$out"/coverage/pictures/view_{front,back,top,below}.png
say '![coverage from the front, back, top and below](guide/guide-coverage.jpg)' ''

say '## 5. A studio session' '' \
  '`rigc studio` serves the scene in the browser: the live view through the camera model with its' \
  'histogram, sliders for every setting, capture, the coverage and the advice as you go' \
  '(docs/commands.md). It runs until stopped, so this page shows the paper'"'"'s scene in it:' '' \
  '![rigc studio](studio.png)' ''

say '## 6. More than the plan: a higher target' '' \
  'The scene'"'"'s shots are the planner'"'"'s for 90 %. Asked for 97 %, `plan` says what stays out' \
  'of reach and what would reach it.' ''
EXIT_ALLOWED=1 LINES_SHOWN=8 show "$rigc" plan "$scene" --target 97% -o "$out/spot-97.yaml"

say '## 7. Two apertures, reconstructed' '' \
  '`rigc sweep` runs variants of the scene and tabulates them; with `eval` each runs COLMAP.' ''
LINES_SHOWN=4 show "$rigc" sweep "$scene" --vary camera.exposure.aperture=f/8,f/20 \
  --measure coverage,eval --scale 0.25 -o "$out/sweep"
sed -n '/^|/p' "$out/sweep/results.md" | head -n 4 >>"$doc"
say ''

say '## 8. The preview against Cycles' '' \
  '`rigc compare` renders with each backend and reconstructs each: the paper'"'"'s Table 1.' ''
LINES_SHOWN=6 show "$rigc" compare "$scene" --backends "preview${reference:+,$reference}" --scale 0.1 \
  -o "$out/compare"

say '## 9. Real photos' '' \
  'Photos of a real object, with a calibration and no scan: `eval --photos` measures their' \
  'registration against the reference cameras, and `twin` makes the capture a scene' \
  '(docs/real-photos.md, docs/twin.md).' ''
temple=tests/real/templeSparseRing
LINES_SHOWN=6 show "$rigc" eval --photos "$temple" --reference-cameras "$temple/templeSR_par.txt" \
  --matcher exhaustive --allow-partial -o "$out/temple"
LINES_SHOWN=4 show "$rigc" twin "$temple" --reference-cameras "$temple/templeSR_par.txt" \
  -o "$out/temple-twin"
oiiotool "$out/temple-twin/contact_sheet.png" --resize 960x0 -o "$pictures/guide-twin.jpg" \
  >/dev/null
say '![each photo beside the twin'"'"'s render of its view](guide/guide-twin.jpg)' ''

mv "$doc" "$guide"
trap - EXIT
echo "guide: wrote $guide"
