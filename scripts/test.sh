#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
# Each phase's wall time, printed as a table however the script ends.
phases=()
phase() {  # name, then the command
  local name=$1 start=$SECONDS status=0
  shift
  "$@" || status=$?
  phases+=("$(printf '%-26s %6d s%s' "$name" $((SECONDS - start)) \
    "$( ((status == 0)) || echo "  (failed: exit $status)")")")
  return $status
}
slurm_started=0
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
finish() {
  if ((slurm_started)); then "${sudo_cmd[@]}" bash scripts/slurm_cluster.sh stop; fi
  printf '\n%-26s %8s\n' phase time
  if ((${#phases[@]})); then printf '%s\n' "${phases[@]}"; fi
  printf '%-26s %6d s\n' total "$SECONDS"
}
trap finish EXIT
phase "setup and build" bash scripts/build.sh
# A single-node Slurm cluster for the tests of `rigc sweep --executor slurm`, stopped however the
# tests end.
phase "slurm cluster" "${sudo_cmd[@]}" bash scripts/slurm_cluster.sh start
slurm_started=1
export SLURM_CONF=${RIGC_SLURM_DIR:-/tmp/rigc-slurm}/slurm.conf
# Tools are installed by setup.sh, so a test that would skip for a missing tool fails here.
RIGC_REQUIRE_TOOLS=1 phase "tests" ctest --test-dir build --output-on-failure -j "$(nproc)"
# The suite under AddressSanitizer + UndefinedBehaviorSanitizer, then a short fuzz run: one clang
# build serves both (build-fuzz/, RIGC_FUZZ=ON: docs/fuzzing.md). RIGC_SANITIZE_TESTS says how
# much: `1` (the default) every label but slow-external, then every fuzz harness for 5 s over its
# corpus and the regression inputs; `fast` the tests labelled fast, then the same fuzz run; `0`
# neither. RIGC_SANITIZE_LABELS=REGEX runs those labels instead.
sanitize=${RIGC_SANITIZE_TESTS:-1}
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
# The same configuration as scripts/fuzz.sh, which then builds only its harnesses.
sanitizer_build() {
  cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only -DNDEBUG" -DRIGC_FUZZ=ON \
    "${launcher[@]}" >/dev/null
  cmake --build build-fuzz -j "$(nproc)" --target rigc_tests rigc
}
phase "sanitizer build" sanitizer_build
ASAN_OPTIONS=abort_on_error=1 LSAN_OPTIONS=suppressions=$PWD/fuzz/lsan.supp \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 RIGC_REQUIRE_TOOLS=1 \
  phase "sanitizer tests" ctest --test-dir build-fuzz --output-on-failure -j "$(nproc)" \
  -LE slow-external ${labels:+-L "$labels"}
# Two harnesses at a time: each fuzzes on one core.
RIGC_FUZZ_JOBS=${RIGC_FUZZ_JOBS:-2} phase "fuzz run" bash scripts/fuzz.sh 5
