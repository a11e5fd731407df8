#!/usr/bin/env bash
# Installs dependencies (scripts/setup.sh), then configures and builds RigC into ./build: the
# targets named (e.g. `rigc rigc_all`, what the demo runs), or every target.
#
# Usage: bash scripts/build.sh [TARGET ...]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
targets=()
if (($#)); then targets=(--target "$@"); fi
cmake --build build -j "$(nproc)" "${targets[@]}"
