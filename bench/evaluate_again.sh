# Sourced by the bench scripts that evaluate sweep variants more than once (COLMAP is not
# deterministic): evaluate_again DIR evaluates every variant of sweep folder DIR until it has
# $evals evaluations (eval, eval2, ...), with $rigc. An evaluation is kept while it is newer
# than the render (a rerun sweep may have rendered again).
evaluate_again() {
  local dir=$1 variant k
  for variant in "$dir"/*/; do
    [[ -f $variant/eval/eval.json ]] || continue
    for ((k = 2; k <= evals; k++)); do
      [[ -f $variant/eval$k/eval.json && ! $variant/manifest.json -nt $variant/eval$k/eval.json ]] &&
        continue
      "$rigc" eval "$variant" -o "$variant/eval$k" >"$variant/eval$k.log" 2>&1 || true
    done
  done
}
