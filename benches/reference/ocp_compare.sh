#!/usr/bin/env bash
# Issue 13's side-by-side run: the quadrotor OCP (12 states, 4 controls, N stages, RK4
# multiple shooting) set up and evaluated by symx (inlined and with call nodes,
# benches/symx_eval.rs, groups ocp_chain_*) and by CasADi SX
# (benches/reference/ocp_chain_casadi.py), in one session; then the peak memory of one
# set-up of each (/usr/bin/time -v, maximum resident set minus the process's baseline);
# then a table of the figures and of the ratios against issue 13's targets.
#
# Run from the repository root on an otherwise idle machine:
#   bash benches/reference/ocp_compare.sh [N=1000] [reps=3]
# Takes about 4 min at N = 1000 (CasADi's 3 set-ups ~1.5 min, symx's inlined ones ~1 min).
# Raw outputs go to target/ocp_compare/ (rust.txt, casadi.json, memory.txt).
set -euo pipefail
N=${1:-1000}
REPS=${2:-3}
OUT=target/ocp_compare
cd "$(dirname "$0")/../.."
mkdir -p "$OUT"

echo "== building the bench" >&2
BIN=$(cargo bench --bench symx_eval --no-run 2>&1 | sed -n 's/.*Executable benches\/symx_eval.rs (\(.*\))/\1/p')
[ -x "$BIN" ] || { echo "could not find the symx_eval bench binary" >&2; exit 1; }

echo "== symx: $BIN -- ocp_chain (N = $N)" >&2
SYMX_OCP_STAGES=$N "$BIN" --bench ocp_chain >"$OUT/rust.txt" 2>&1

echo "== CasADi: ocp_chain_casadi.py $N $REPS" >&2
python3 benches/reference/ocp_chain_casadi.py "$N" "$REPS" >"$OUT/casadi.json"

echo "== peak memory (one set-up each)" >&2
peak() { /usr/bin/time -v "$@" 2>&1 >/dev/null | sed -n 's/.*Maximum resident set size (kbytes): //p'; }
{
  echo "symx_none $(SYMX_OCP_MEMORY=none peak "$BIN")"
  echo "symx_inlined $(SYMX_OCP_STAGES=$N SYMX_OCP_MEMORY=inlined peak "$BIN")"
  echo "symx_calls $(SYMX_OCP_STAGES=$N SYMX_OCP_MEMORY=calls peak "$BIN")"
  echo "casadi_none $(peak python3 -c 'import casadi')"
  echo "casadi_sx $(peak python3 benches/reference/ocp_chain_casadi.py "$N" memory)"
} >"$OUT/memory.txt"

python3 - "$OUT" "$N" <<'EOF'
import json, re, sys
out, n = sys.argv[1], sys.argv[2]
rust = open(f"{out}/rust.txt").read()
cas = json.load(open(f"{out}/casadi.json"))
mem = dict(line.split() for line in open(f"{out}/memory.txt") if line.strip())
mem = {k: int(v) / 1024 for k, v in mem.items()}  # MiB

setup, evals, nodes = {}, {}, {}
for v in ("inlined", "calls"):
    m = re.search(rf"ocp_chain_{v} setup_ms (\{{.*?\}})", rust)
    setup[v] = json.loads(m.group(1))
    evals[v] = {f: float(re.search(rf"ocp_chain_{v} {f}\s+per-call median\s+([\d.]+) us", rust).group(1))
                for f in ("grad_f", "jac_g", "hess_L")}
    nodes[v] = int(re.search(rf"ocp_chain_{v}: graph after .*?: (\d+) nodes", rust).group(1))
c_setup = cas["median_ms"]
c_eval = {f: cas["eval"][f]["internal_us"] for f in ("grad_f", "jac_g", "hess_L")}

def row(name, a, b, c, unit):
    r = lambda x, y: f"{x / y:8.3f}" if y else "       -"
    print(f"| {name:22} | {a:12.3f} | {b:12.3f} | {c:12.3f} | {r(a, c)} | {r(b, c)} | {r(a, b)} | {unit}")

print(f"\nquadrotor OCP, N = {n}: symx inlined / symx calls / CasADi SX (inlined)")
print("| quantity               |  symx inlined |   symx calls |    CasADi SX | inl/CasADi | calls/CasADi | inl/calls | unit")
print("|---|---|---|---|---|---|---|---|")
phases = [("build", "build"), ("grad_f", "grad_f"), ("jac_g", "jac_g"), ("hess_L", "hess_L"),
          ("functions", "functions"), ("total", "total")]
for p, q in phases:
    row(f"set-up {p}", setup["inlined"][p], setup["calls"][p], c_setup[q], "ms (median)")
for f in ("grad_f", "jac_g", "hess_L"):
    row(f"eval {f}", evals["inlined"][f], evals["calls"][f], c_eval[f], "us per call (median)")
base_s, base_c = mem["symx_none"], mem["casadi_none"]
row("peak memory of set-up", mem["symx_inlined"] - base_s, mem["symx_calls"] - base_s,
    mem["casadi_sx"] - base_c, "MiB (max RSS - baseline)")
print(f"| graph nodes            | {nodes['inlined']:12d} | {nodes['calls']:12d} |            - |")

print("\nissue 13 targets:")
best = min(setup["inlined"]["total"], setup["calls"]["total"])
print(f"  set-up total <= 0.2x CasADi SX:      inlined {setup['inlined']['total'] / c_setup['total']:.3f}x,"
      f" calls {setup['calls']['total'] / c_setup['total']:.3f}x  -> {'met' if best <= 0.2 * c_setup['total'] else 'NOT met'}")
ct = setup["inlined"]["functions"] / setup["calls"]["functions"]
mt = (mem["symx_inlined"] - base_s) / (mem["symx_calls"] - base_s)
print(f"  calls: compile time >= 5x below inlined: {ct:.1f}x -> {'met' if ct >= 5 else 'NOT met'};"
      f" memory >= 5x below: {mt:.1f}x -> {'met' if mt >= 5 else 'NOT met'}")
for v in ("inlined", "calls"):
    h = evals[v]["hess_L"] / c_eval["hess_L"]
    print(f"  hess_L evaluation ({v}) no slower than CasADi's SX VM: {h:.3f}x -> {'met' if h <= 1 else 'NOT met'}")
print("  checksums: CasADi", cas["checksum"], "(symx's are in target/ocp_compare/rust.txt)")
EOF
