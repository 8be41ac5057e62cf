#!/usr/bin/env python3
"""IPOPT's iteration log on one exported corpus formulation, for side-by-side comparisons.

Solves the dump of `corpus export NAME` (the same text corpus_ipopt.py parses, so the same
expressions in the same order) with IPOPT at the corpus settings (tol 1e-8, exact Hessian,
MUMPS, max_iter 3000), with extra IPOPT options and an optional perturbation of x0, and
prints IPOPT's own log (print_level 5 by default) and one summary line.

Usage:
  target/release/corpus export noncvxu2_1000 > /tmp/u2.json
  python3 benches/reference/ipopt_trace.py /tmp/u2.json [--print-level 5] \\
      [--perturb 1e-12] [--opt mu_strategy=monotone ...] [--records FILE]

--records FILE writes CasADi's per-iteration stats (full precision) as JSON lines, the
fields named as in `corpus trace`'s records (iter, objective, inf_pr, inf_du, mu, d_norm,
regularization, alpha_du, alpha_pr; CasADi does not record ls).

--perturb EPS multiplies x0[i] by (1 + EPS * s_i), s_i = +1, -1, +1, ... (deterministic).
"""
import argparse
import json
import math
import os
import sys
import threading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gap_crossing_casadi as gc  # noqa: E402  (the symx-text parser)


def value(text):
    for conv in (int, float):
        try:
            return conv(text)
        except ValueError:
            pass
    return text


def run(a):
    d = json.load(open(a.dump))
    x = gc.ca.SX.sym("x", d["n"])
    p = gc.Parser({v["name"]: x[i] for i, v in enumerate(d["variables"])})
    f = p.parse(d["objective"])
    g = gc.ca.vertcat(*[p.parse(c["expr"]) for c in d["constraints"]])
    inf = math.inf
    opts = {"ipopt.tol": 1e-8, "ipopt.print_level": a.print_level, "ipopt.max_iter": 3000,
            "ipopt.sb": "yes", "print_time": False}
    for kv in a.opt:
        k, v = kv.split("=", 1)
        opts["ipopt." + k] = value(v)
    S = gc.ca.nlpsol("S", "ipopt", {"x": x, "f": f, "g": g}, opts)
    x0 = [v["x0"] for v in d["variables"]]
    x0 = [v * (1.0 + a.perturb * (1 if i % 2 == 0 else -1)) for i, v in enumerate(x0)]
    r = S(x0=x0,
          lbx=[gc.bound(v["lower"], -inf) for v in d["variables"]],
          ubx=[gc.bound(v["upper"], inf) for v in d["variables"]],
          lbg=[gc.bound(c["lower"], -inf) for c in d["constraints"]],
          ubg=[gc.bound(c["upper"], inf) for c in d["constraints"]])
    st = S.stats()
    if a.records:
        it = st["iterations"]
        names = {"obj": "objective", "inf_pr": "inf_pr", "inf_du": "inf_du", "mu": "mu", "d_norm": "d_norm",
                 "regularization_size": "regularization", "alpha_du": "alpha_du", "alpha_pr": "alpha_pr"}
        with open(a.records, "w") as fh:
            for k in range(len(it["obj"])):
                rec = {"iter": k}
                rec.update({ours: it[theirs][k] for theirs, ours in names.items()})
                fh.write(json.dumps(rec) + "\n")
    out = {"status": st["return_status"], "iterations": st["iter_count"],
           "objective": float(r["f"]), "perturb": a.perturb, "opts": a.opt}
    if a.print_x:
        out["x"] = r["x"].full().ravel().tolist()
    print(json.dumps(out))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dump", help="JSON written by `corpus export NAME`")
    ap.add_argument("--print-level", type=int, default=5)
    ap.add_argument("--perturb", type=float, default=0.0, help="relative perturbation of x0")
    ap.add_argument("--records", help="write the per-iteration stats here (JSON lines)")
    ap.add_argument("--print-x", action="store_true", help="also print the final x (e.g. with --opt max_iter=K)")
    ap.add_argument("--opt", action="append", default=[], help="extra IPOPT option NAME=VALUE")
    a = ap.parse_args()
    sys.setrecursionlimit(1_000_000)
    threading.stack_size(512 * 1024 * 1024)
    t = threading.Thread(target=run, args=(a,))
    t.start()
    t.join()


if __name__ == "__main__":
    main()
