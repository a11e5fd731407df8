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
# RIGC_SANITIZE_TESTS=1: the same suite under AddressSanitizer + UndefinedBehaviorSanitizer
# (build-asan/, GCC: docs/fuzzing.md), but the slow-external tests; then every fuzz harness for a
# few seconds over its corpus and the regression inputs (build-fuzz/, clang). Opt-in: with the
# normal suite it does not fit in CI's 90 minutes (docs/fuzzing.md); the regression inputs replay
# in the suite above regardless. RIGC_SANITIZE_LABELS=fast runs only the `fast` tests under it.
if [[ ${RIGC_SANITIZE_TESTS:-0} == 1 ]]; then
  launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRIGC_SANITIZE=ON \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" "${launcher[@]}" >/dev/null
  cmake --build build-asan -j "$(nproc)"
  ASAN_OPTIONS=abort_on_error=1 LSAN_OPTIONS=suppressions=$PWD/fuzz/lsan.supp \
    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 RIGC_REQUIRE_TOOLS=1 \
    ctest --test-dir build-asan --output-on-failure -j "$(nproc)" -LE slow-external \
    ${RIGC_SANITIZE_LABELS:+-L "$RIGC_SANITIZE_LABELS"}
  bash scripts/fuzz.sh 5
fi
