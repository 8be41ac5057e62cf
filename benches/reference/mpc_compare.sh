#!/usr/bin/env bash
# The MPC examples side by side: symnlp (IPM, SQP, RTI) and CasADi 3.8.2 (IPOPT, sqpmethod +
# qrqp, RTI = sqpmethod max_iter 1 + qrqp) on identical transcriptions, plants and warm
# starts (examples/mpc_*.rs, benches/reference/mpc_casadi.py), in ROUNDS interleaved
# rounds; prints per configuration the median over rounds of the per-step latency median
# and max, the warm steps' max over their median (every step but the cold first one, the
# loop's initialisation), the iterations, the closed-loop cost, and the ratios to symnlp's IPM and to
# CasADi's RTI; for symnlp's RTI also the feedback phase's median (the latency from the
# measured state to the control when the preparation runs ahead) and its share of the
# step. Both RTIs converge their first step (sqpmethod / the IPM) and take one iteration
# per later step.
# symnlp runs each method twice: on the tape (its default evaluator) and with `--jit`
# (`Mpc::with_evaluator(Evaluator::Jit)`, rows `ipm_jit`, `sqp_jit`, `rti_jit`: the same
# iterates bit for bit); the JIT's compile time is printed apart (it is not part of any
# step) with the number of steps after which the per-step saving repays it. CasADi runs as
# a user runs it by default: SX functions on its virtual machine, no `jit` option.
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
# The workspace's feature set (as `cargo build --release --workspace`), so that no
# dependency is rebuilt with another one.
cargo build --release -q --workspace --examples
: > "$OUT"
for round in $(seq 1 "$ROUNDS"); do
    for p in ${PROBLEMS//,/ }; do
        for s in ipm sqp rti "ipm --jit" "sqp --jit" "rti --jit"; do
            # shellcheck disable=SC2086 # "$s" is a method and an optional --jit
            if ! timeout "$SQP_TIMEOUT" "target/release/examples/mpc_$p" $s --json 2>/dev/null \
                | sed "s/^{/{\"round\":$round,/" >> "$OUT"; then
                echo "{\"round\":$round,\"problem\":\"$p\",\"solver\":\"${s/ --jit/_jit}\",\"timed_out\":$SQP_TIMEOUT}" >> "$OUT"
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
print("symnlp: tape rows ipm/sqp/rti, native rows *_jit (same iterates); CasADi: SX on its VM (default, no jit)")
print(f"| problem | solver | median ms | max ms | warm steps: max / median | feedback median ms (share of step) | iterations mean / max | all steps succeeded | closed-loop cost | median / symnlp IPM's | median / CasADi RTI's | jit compile ms (repaid after steps) |")
print("|---|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|")
for (p, s), rs in by.items():
    ok = [r for r in rs if "median_ms" in r]
    if not ok:
        print(f"| {p} | {s} | timed out ({rs[0]['timed_out']} s) | | | | | | | | | |")
        continue
    med = statistics.median(r["median_ms"] for r in ok)
    mx = statistics.median(r["max_ms"] for r in ok)
    ipm = [r["median_ms"] for r in by.get((p, "ipm"), []) if "median_ms" in r]
    ratio = med / statistics.median(ipm) if ipm else float("nan")
    crti = [r["median_ms"] for r in by.get((p, "casadi_rti"), []) if "median_ms" in r]
    ratio_rti = med / statistics.median(crti) if crti else float("nan")
    fb = ""
    if s.startswith("rti"):
        fbm = statistics.median(r["feedback_median_ms"] for r in ok)
        later = statistics.median(r["later_median_ms"] for r in ok)
        fb = f"{fbm:.3f} ({100 * fbm / later:.0f} %)"
    jit = ""
    if s.endswith("_jit"):
        comp = statistics.median(r["jit_compile_ms"] for r in ok)
        tape = [r["median_ms"] for r in by.get((p, s[:-4]), []) if "median_ms" in r]
        saving = statistics.median(tape) - med if tape else float("nan")
        jit = f"{comp:.0f} ({comp / saving:.0f})" if saving > 0 else f"{comp:.0f} (never)"
    # The warm steps (all but the cold first one, the loop's initialisation): the spread
    # the SQP target "max <= 5x its own median" is about.
    warm_spread = statistics.median(r["warm_max_ms"] / r["warm_median_ms"] for r in ok)
    r = ok[0]
    print(f"| {p} | {s} | {med:.2f} | {mx:.1f} | {warm_spread:.1f} | {fb} | {r['iterations_mean']:.2f} / {r['iterations_max']} "
          f"| {r['all_succeeded']} | {r['closed_loop_cost']:.10g} | {ratio:.2f} | {ratio_rti:.2f} | {jit} |")
PY
