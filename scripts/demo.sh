#!/usr/bin/env bash
# Sets up, builds and runs RigC on the paper's capture rig (scenes/paper-turntable.yaml).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
scene=scenes/paper-turntable.yaml
out=out/paper-turntable
mkdir -p "$out"
./build/rigc check "$scene"
./build/rigc compile "$scene" --target ir -o "$out/scene.ir.json"
echo "demo: the compiled scene (IR, SI units) is in $out/scene.ir.json"
