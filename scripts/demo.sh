#!/usr/bin/env bash
# Sets up, builds and runs RigC on the paper's capture rig (scenes/paper-turntable.yaml):
# checks it, renders every shot with the fast preview, and analyses the coverage.
set -euo pipefail
cd "$(dirname "$0")/.."
# The binaries alone: the tests' binary is scripts/test.sh's.
bash scripts/build.sh rigc rigc_all
scene=scenes/paper-turntable.yaml
out=out/paper-turntable
mkdir -p out
./build/rigc check "$scene"
./build/rigc compile "$scene" --target ir --no-geometry -o "$out.ir.json"
# A quarter of the Canon 6D's resolution keeps the demo quick; drop --scale for full size.
./build/rigc render "$scene" --backend preview --scale 0.25 -o "$out/preview"
./build/rigc coverage "$scene" -o "$out/coverage"
echo "demo: photos in $out/preview/images, ground-truth poses in $out/preview/sparse,"
echo "      coverage pictures in $out/coverage/pictures, the IR in $out.ir.json"
