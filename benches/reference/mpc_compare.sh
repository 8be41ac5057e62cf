#!/usr/bin/env bash
# The MPC examples side by side: symnlp (IPM, SQP, RTI) and CasADi 3.8.2 (IPOPT, sqpmethod +
# qrqp, RTI = sqpmethod max_iter 1 + qrqp) on identical transcriptions, plants and warm
# starts (examples/mpc_*.rs, benches/reference/mpc_casadi.py), in ROUNDS interleaved
# rounds; prints per configuration the median over rounds of the per-step latency median
# and max, the iterations, the closed-loop cost, and the ratios to symnlp's IPM and to
# CasADi's RTI; for symnlp's RTI also the feedback phase's median (the latency from the
# measured state to the control when the preparation runs ahead) and its share of the
# step. Both RTIs converge their first step (sqpmethod / the IPM) and take one iteration
# per later step.
# fatrop is not in CasADi's PyPI wheel's plugin list here, so it is not run.
# Usage: bash benches/reference/mpc_compare.sh [ROUNDS=3] [PROBLEMS=cart_pole,car,quadrotor]
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
ROUNDS="${1:-3}"
PROBLEMS="${2:-cart_pole,car,quadrotor}"
SQP_TIMEOUT="${SQP_TIMEOUT:-120}"
OUT="${OUT:-$HERE/results/mpc_compare.jsonl}"
cd "$ROOT"
cargo build --release -q -p symnlp-examples --example mpc_cart_pole --example mpc_car --example mpc_quadrotor
: > "$OUT"
for round in $(seq 1 "$ROUNDS"); do
    for p in ${PROBLEMS//,/ }; do
        for s in ipm sqp rti; do
            if ! timeout "$SQP_TIMEOUT" "target/release/examples/mpc_$p" "$s" --json 2>/dev/null \
                | sed "s/^{/{\"round\":$round,/" >> "$OUT"; then
                echo "{\"round\":$round,\"problem\":\"$p\",\"solver\":\"$s\",\"timed_out\":$SQP_TIMEOUT}" >> "$OUT"
            fi
        done
        (cd "$HERE" && python3 mpc_casadi.py "$p" ipopt,sqp,rti) \
            | sed "s/^{/{\"round\":$round,/; s/\"solver\": \"/\"solver\": \"casadi_/" >> "$OUT"
    done
done
python3 - "$OUT" <<'PY'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
by = {}
for r in rows:
    by.setdefault((r["problem"], r["solver"]), []).append(r)
print(f"| problem | solver | median ms | max ms | feedback median ms (share of step) | iterations mean / max | all steps succeeded | closed-loop cost | median / symnlp IPM's | median / CasADi RTI's |")
print("|---|---|---:|---:|---:|---:|---|---:|---:|---:|")
for (p, s), rs in by.items():
    ok = [r for r in rs if "median_ms" in r]
    if not ok:
        print(f"| {p} | {s} | timed out ({rs[0]['timed_out']} s) | | | | | | | |")
        continue
    med = statistics.median(r["median_ms"] for r in ok)
    mx = statistics.median(r["max_ms"] for r in ok)
    ipm = [r["median_ms"] for r in by.get((p, "ipm"), []) if "median_ms" in r]
    ratio = med / statistics.median(ipm) if ipm else float("nan")
    crti = [r["median_ms"] for r in by.get((p, "casadi_rti"), []) if "median_ms" in r]
    ratio_rti = med / statistics.median(crti) if crti else float("nan")
    fb = ""
    if s == "rti":
        fbm = statistics.median(r["feedback_median_ms"] for r in ok)
        later = statistics.median(r["later_median_ms"] for r in ok)
        fb = f"{fbm:.3f} ({100 * fbm / later:.0f} %)"
    r = ok[0]
    print(f"| {p} | {s} | {med:.2f} | {mx:.1f} | {fb} | {r['iterations_mean']:.2f} / {r['iterations_max']} "
          f"| {r['all_succeeded']} | {r['closed_loop_cost']:.10g} | {ratio:.2f} | {ratio_rti:.2f} |")
PY
