#!/usr/bin/env bash
# nlp::integrator (DOPRI5 and SDIRK4) against CasADi 3.8.2 / CVODES, same tolerances, run back to back
# twice each (interleaved) on the same machine. Usage: bash benches/reference/integrator_compare.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release -p symnlp-examples --example integrator_compare -q
for round in 1 2; do
    echo "== round $round: symnlp"
    target/release/examples/integrator_compare
    echo "== round $round: CVODES"
    python3 benches/reference/integrator_casadi.py | python3 -c '
import json, sys
for k, v in json.load(sys.stdin).items():
    err = max(abs(a - b) for a, b in zip(v["xf_rtol1e-6"], v["xf_ref"]))
    steps, median = v["cvodes_rtol1e-6_steps"], v["cvodes_rtol1e-6_median_s"]
    print(f"{k}: max |error| {err:.2e}, steps {steps}, median {median:.6f} s")'
done
