#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
# A single-node Slurm cluster for the tests of `rigc sweep --executor slurm`, stopped however the
# tests end.
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
"${sudo_cmd[@]}" bash scripts/slurm_cluster.sh start
trap '"${sudo_cmd[@]}" bash scripts/slurm_cluster.sh stop' EXIT
export SLURM_CONF=${RIGC_SLURM_DIR:-/tmp/rigc-slurm}/slurm.conf
# Tools are installed by setup.sh, so a test that would skip for a missing tool fails here.
RIGC_REQUIRE_TOOLS=1 ctest --test-dir build --output-on-failure -j "$(nproc)"
