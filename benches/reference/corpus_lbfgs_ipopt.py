#!/usr/bin/env python3
"""IPOPT's limited-memory mode on the smallest instance of every optimal-control family
of the corpus (reference for corpus/tests/lbfgs.rs and docs/solvers.md, "Limited-memory
Hessian").

Each instance is exported by the Rust binary (`corpus export NAME`, the formulation
symnlp solves), parsed into CasADi SX by the parser of gap_crossing_casadi.py (as
corpus_ipopt.py does) and solved by IPOPT twice: exact Hessian and
hessian_approximation = limited-memory (IPOPT's defaults otherwise: BFGS, history 6,
scalar1), tol 1e-8, max_iter 3000.

Usage:
  cargo build --release -p corpus
  python3 benches/reference/corpus_lbfgs_ipopt.py --bin target/release/corpus \\
      > benches/reference/results/corpus_lbfgs_ipopt.jsonl

One JSON line per instance: {"instance", "n", "m", "exact": {...}, "limited_memory": {...}}
with status, iterations and objective.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import threading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gap_crossing_casadi as gc  # noqa: E402

ca = gc.ca


def smallest_ocp(binary):
    out = subprocess.run([binary, "list", "--kind", "ocp"], check=True, stdout=subprocess.PIPE, text=True).stdout
    rows = [json.loads(line) for line in out.splitlines() if line.strip()]
    first = {}
    for r in rows:  # families are listed smallest size first
        first.setdefault(r["family"], r)
    return list(first.values())


def solve(d, hessian):
    x = ca.SX.sym("x", d["n"])
    p = gc.Parser({v["name"]: x[i] for i, v in enumerate(d["variables"])})
    f = p.parse(d["objective"])
    g = ca.vertcat(*[p.parse(c["expr"]) for c in d["constraints"]])
    opts = {"ipopt.tol": 1e-8, "ipopt.print_level": 0, "ipopt.max_iter": 3000,
            "ipopt.hessian_approximation": hessian, "ipopt.sb": "yes", "print_time": False}
    S = ca.nlpsol("S", "ipopt", {"x": x, "f": f, "g": g}, opts)
    inf = math.inf
    r = S(x0=[v["x0"] for v in d["variables"]],
          lbx=[gc.bound(v["lower"], -inf) for v in d["variables"]],
          ubx=[gc.bound(v["upper"], inf) for v in d["variables"]],
          lbg=[gc.bound(c["lower"], -inf) for c in d["constraints"]],
          ubg=[gc.bound(c["upper"], inf) for c in d["constraints"]])
    st = S.stats()
    return {"status": st["return_status"], "iterations": int(st["iter_count"]), "objective": float(r["f"])}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="target/release/corpus", help="the corpus binary")
    a = ap.parse_args()
    sys.setrecursionlimit(1_000_000)
    threading.stack_size(512 * 1024 * 1024)
    for inst in smallest_ocp(a.bin):
        name = inst["instance"]
        d = json.loads(subprocess.run([a.bin, "export", name], check=True, stdout=subprocess.PIPE).stdout)
        res = {}

        def work():
            res["exact"] = solve(d, "exact")
            res["limited_memory"] = solve(d, "limited-memory")

        # Deeply nested sums: parse recursively on a thread with a large stack.
        t = threading.Thread(target=work)
        t.start()
        t.join()
        print(json.dumps({"instance": name, "n": d["n"], "m": d["m"], **res}), flush=True)


if __name__ == "__main__":
    main()
