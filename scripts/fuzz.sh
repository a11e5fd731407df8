#!/usr/bin/env bash
# Builds the libFuzzer harnesses (fuzz/, docs/fuzzing.md) into build-fuzz/ and runs each for
# SECONDS (default 60) under `nice`, starting from its corpus: the seeds (scenes/, tests/bad_scenes/,
# Debian's assimp-testmodels, fuzz/seeds/), the inputs found so far (build-fuzz/fuzz-corpus/) and
# the regression inputs (tests/fuzz_regressions/). Every crash, hang (> 10 s) or out-of-memory
# (> 2 GB) becomes a regression input under tests/fuzz_regressions/<harness>/, which rigc_tests
# replays; the script then exits 1.
#   RIGC_FUZZ_ONLY="scene ply"  run only these harnesses
#   RIGC_FUZZ_JOBS=2            run this many harnesses at once (default 1)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
build=build-fuzz
harnesses=(${RIGC_FUZZ_ONLY:-scene ply obj stl gltf texture colmap_cameras colmap_images colmap_points manifest studio_edits})

launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only -DNDEBUG" -DRIGC_FUZZ=ON \
  "${launcher[@]}" >/dev/null
nice -n 10 cmake --build "$build" -j "$(nproc)" --target "${harnesses[@]/#/fuzz_}"

models=/usr/share/assimp/models
# Copies the files given (each under 64 KB) into the seed folder $1.
seed() {
  local dir=$1
  shift
  mkdir -p "$dir"
  find "$@" -type f -size -64k -exec cp -t "$dir" {} + 2>/dev/null || true
}
# Seed folder and dictionary of a harness.
prepare_seeds() {
  local h=$1 dir=$build/fuzz-seeds/$1
  rm -rf "$dir"
  mkdir -p "$dir"
  case $h in
    scene) seed "$dir" scenes tests/bad_scenes -name '*.yaml' ;;
    ply) seed "$dir" "$models" -iname '*.ply' ;;
    obj) seed "$dir" "$models" -iname '*.obj' ;;
    stl) seed "$dir" "$models" -iname '*.stl' ;;
    gltf) seed "$dir" "$models" '(' -iname '*.gltf' -o -iname '*.glb' ')' ;;
    texture) seed "$dir" "$models" '(' -iname '*.png' -o -iname '*.jpg' -o -iname '*.bmp' \
      -o -iname '*.tga' ')' ;;
  esac
  if [[ -d fuzz/seeds/$h ]]; then cp -r fuzz/seeds/$h/. "$dir"; fi
}
dictionary() {
  case $1 in
    colmap_*) echo fuzz/colmap.dict ;;
    texture) echo "" ;;
    *) echo "fuzz/$1.dict" ;;
  esac
}

# Runs one harness; its log is $build/fuzz-logs/<harness>.log.
run_harness() {
  local h=$1 corpus=$build/fuzz-corpus/$1 artifacts=$build/fuzz-artifacts/$1/
  local regressions=tests/fuzz_regressions/$1 tmp=$build/fuzz-tmp/$1 dict
  dict=$(dictionary "$h")
  mkdir -p "$corpus" "$artifacts" "$regressions" "$tmp"
  prepare_seeds "$h"
  local args=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$artifacts"
    -print_final_stats=1)
  if [[ -n $dict ]]; then args+=(-dict="$dict"); fi
  TMPDIR=$(realpath "$tmp") LSAN_OPTIONS=suppressions=$PWD/fuzz/lsan.supp nice -n 10 "$build/fuzz/fuzz_$h" "${args[@]}" "$corpus" \
    "$build/fuzz-seeds/$h" "$regressions" >"$build/fuzz-logs/$h.log" 2>&1 || true
  rm -rf "$tmp"
}

# One line per harness: executions, corpus, findings (new files in tests/fuzz_regressions/).
summarize() {
  local h=$1 log=$build/fuzz-logs/$1.log status
  status=$(grep -oE '#[0-9]+: cov: .*' "$log" | tail -n 1 || true)
  local found=0
  for f in "$build/fuzz-artifacts/$h"/*; do
    [[ -f $f ]] || continue
    local name
    name=$(basename "$f")
    if [[ ! -e tests/fuzz_regressions/$h/$name ]]; then
      cp "$f" "tests/fuzz_regressions/$h/$name"
      found=$((found + 1))
    fi
  done
  printf '%-15s %s new findings: %d\n' "$h" "${status:-no status (see $log)}" "$found"
  return $((found > 0))
}

mkdir -p "$build/fuzz-logs"
jobs_max=${RIGC_FUZZ_JOBS:-1}
for h in "${harnesses[@]}"; do
  while (($(jobs -rp | wc -l) >= jobs_max)); do wait -n || true; done
  echo "fuzz: $h for ${seconds} s"
  run_harness "$h" &
done
wait

failed=0
echo "fuzz: harness, last status (#executions, coverage, corpus, exec/s, oom/timeout/crash)"
for h in "${harnesses[@]}"; do summarize "$h" || failed=1; done
if ((failed)); then
  echo "fuzz: new findings copied to tests/fuzz_regressions/ (logs in $build/fuzz-logs/)" >&2
fi
exit $failed
