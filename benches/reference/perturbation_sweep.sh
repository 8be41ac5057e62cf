#!/bin/bash
# Both solvers from starting points perturbed by a few ulps: x0[i] *= 1 + k·1e-15·(+1, −1, …)
# for k = 0, ±1, …, ±K (`corpus trace --perturb`, `ipopt_trace.py --perturb`), one JSON line
# per solve on stdout: {"solver", "inst", "r": {status, iterations, objective, perturb}}.
# Shows whether the local minimum an instance ends in is decided by round-off
# (docs/performance.md, "noncvxu2 / noncvxun: minima decided by round-off").
#
# Usage (from the repository root, after `cargo build --release -p corpus`):
#   benches/reference/perturbation_sweep.sh K INSTANCE... > results.jsonl
# Extra symnlp options: SYMNLP_OPTS="--opt perturbation_skip_zero_after=0" (the label
# symnlp plus the options); IPOPT is skipped with NO_IPOPT=1.
set -euo pipefail
K=$1; shift
BIN=${BIN:-target/release/corpus}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
label=symnlp; [ -n "${SYMNLP_OPTS:-}" ] && label="symnlp $SYMNLP_OPTS"
for inst in "$@"; do
  "$BIN" export "$inst" > "$tmp/dump.json"
  for k in $(seq -"$K" "$K"); do
    [ "$k" = "-0" ] && k=0
    e="${k}e-15"
    # shellcheck disable=SC2086
    echo "{\"solver\":\"$label\",\"inst\":\"$inst\",\"r\":$("$BIN" trace "$inst" --perturb="$e" ${SYMNLP_OPTS:-} | tail -1)}"
    if [ -z "${NO_IPOPT:-}" ]; then
      echo "{\"solver\":\"ipopt\",\"inst\":\"$inst\",\"r\":$(python3 benches/reference/ipopt_trace.py "$tmp/dump.json" --print-level 0 --perturb="$e" 2>/dev/null | tail -1)}"
    fi
  done
done
