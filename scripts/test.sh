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
# The suite under AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/, GCC: docs/fuzzing.md).
# RIGC_SANITIZE_TESTS says how much of it: `0` (the default) none; `fast` the tests labelled fast;
# `1` every label but slow-external, then every fuzz harness for a few seconds over its corpus and
# the regression inputs (build-fuzz/, clang). RIGC_SANITIZE_LABELS=REGEX runs those labels instead.
# Opt-in until one whole sanitizer run has passed (docs/fuzzing.md: "What the sanitizer build
# costs").
sanitize=${RIGC_SANITIZE_TESTS:-0}
case $sanitize in
  0) exit 0 ;;
  fast) labels=${RIGC_SANITIZE_LABELS:-fast} ;;
  1) labels=${RIGC_SANITIZE_LABELS:-} ;;
  *)
    echo "scripts/test.sh: RIGC_SANITIZE_TESTS is 0, fast or 1, not '$sanitize'" >&2
    exit 1
    ;;
esac
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRIGC_SANITIZE=ON \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" "${launcher[@]}" >/dev/null
cmake --build build-asan -j "$(nproc)" --target rigc_tests
ASAN_OPTIONS=abort_on_error=1 LSAN_OPTIONS=suppressions=$PWD/fuzz/lsan.supp \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 RIGC_REQUIRE_TOOLS=1 \
  ctest --test-dir build-asan --output-on-failure -j "$(nproc)" -LE slow-external \
  ${labels:+-L "$labels"}
if [[ $sanitize == 1 ]]; then bash scripts/fuzz.sh 5; fi
