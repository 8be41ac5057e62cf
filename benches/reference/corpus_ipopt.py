#!/usr/bin/env python3
"""symnlp's IPM and IPOPT on the same corpus formulations, in one run (docs/corpus.md).

For every selected instance of the corpus (crate `corpus/`), the Rust binary `corpus export
NAME --solve` builds the problem with nlp::Problem, solves it with symnlp's interior-point
method and prints the problem as text (symx's printed expressions, bounds, x0, values at x0)
together with symnlp's outcome. This script parses that text into CasADi SX with the parser of
gap_crossing_casadi.py (no second formulation that could drift), checks f(x0) and g(x0)
against symnlp's values, and solves it with nlpsol('ipopt'): tol 1e-8, exact Hessian, MUMPS,
IPOPT's defaults otherwise, max_iter 3000, same x0 and bounds. One JSON line per instance goes
to --out: {"instance", "symnlp": {...}, "ipopt": {...}}.

The run is resumable: instances already in --out are skipped (delete the file, or pass
--fresh, to re-measure). Wall times are those of a shared machine unless you made it quiet.

Usage:
  cargo build --release -p corpus
  python3 benches/reference/corpus_ipopt.py --bin target/release/corpus \\
      --out benches/reference/results/corpus.jsonl [--filter rocket,glider] [--kind ocp] \\
      [--max-n 5000] [--max-wall 600]
  target/release/corpus report benches/reference/results/corpus.jsonl --svg-dir docs
  # how the iterations went, for a few instances (symnlp: `corpus diagnose`; IPOPT: the
  # per-iteration stats CasADi records):
  python3 benches/reference/corpus_ipopt.py --diagnose --out results/corpus_diagnosis.jsonl \
      --filter rocket_trap_400,race_car_rk4_400
"""
import argparse
import json
import os
import subprocess
import sys
import threading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gap_crossing_casadi  # noqa: E402  (the symx-text parser and the IPOPT solve)


def listing(a):
    cmd = [a.bin, "list"]
    for flag, v in (("--filter", a.filter), ("--kind", a.kind), ("--max-n", a.max_n)):
        if v is not None:
            cmd += [flag, str(v)]
    out = subprocess.run(cmd, check=True, stdout=subprocess.PIPE, text=True).stdout
    return [json.loads(l) for l in out.splitlines() if l.strip()]


def ipopt_on(d, a):
    result = {}

    def work():
        result["r"] = gap_crossing_casadi.solve(d, 1, a.print_level, 3000, a.max_wall)

    # Deeply nested sums: parse recursively on a thread with a large stack.
    t = threading.Thread(target=work)
    t.start()
    t.join()
    if "r" not in result:
        raise RuntimeError("IPOPT side failed (see the traceback above)")
    r = result["r"]
    run = r["runs"][0]
    return {
        "status": run["status"],
        "success": run["status"] in ("Solve_Succeeded", "Solved_To_Acceptable_Level"),
        "iterations": run["iterations"],
        "objective": run["objective"],
        "constr_viol": run["constr_viol"],
        "solve_s": run["solve_s"],
        "build_s": r["build_s"],
        "nlpsol_s": r["nlpsol_s"],
        "f0_error": r["f0_error"],
        "g0_error": r["g0_error"],
    }


def ipopt_diagnosis(d, a):
    """IPOPT's per-iteration records summarised like corpus::diagnose::Diagnosis."""
    x = gap_crossing_casadi.ca.SX.sym("x", d["n"])
    p = gap_crossing_casadi.Parser({v["name"]: x[i] for i, v in enumerate(d["variables"])})
    f = p.parse(d["objective"])
    g = gap_crossing_casadi.ca.vertcat(*[p.parse(c["expr"]) for c in d["constraints"]])
    bound = gap_crossing_casadi.bound
    inf = float("inf")
    opts = {"ipopt.tol": 1e-8, "ipopt.print_level": 0, "ipopt.max_iter": 3000,
            "ipopt.max_wall_time": a.max_wall, "ipopt.sb": "yes", "print_time": False}
    S = gap_crossing_casadi.ca.nlpsol("S", "ipopt", {"x": x, "f": f, "g": g}, opts)
    S(x0=[v["x0"] for v in d["variables"]],
      lbx=[bound(v["lower"], -inf) for v in d["variables"]], ubx=[bound(v["upper"], inf) for v in d["variables"]],
      lbg=[bound(c["lower"], -inf) for c in d["constraints"]], ubg=[bound(c["upper"], inf) for c in d["constraints"]])
    st = S.stats()
    it = st["iterations"]
    alpha, reg = it["alpha_pr"][1:], it["regularization_size"][1:]
    return {
        "status": st["return_status"],
        "iterations": st["iter_count"],
        "tiny_alpha": sum(1 for v in alpha if v < 1e-8),
        "small_alpha": sum(1 for v in alpha if v < 1e-3),
        "regularized": sum(1 for v in reg if v > 0),
        "max_regularization": max(reg, default=0.0),
        "final_mu": it["mu"][-1],
        "final_inf_pr": it["inf_pr"][-1],
        "final_inf_du": it["inf_du"][-1],
    }


def diagnose(inst, a):
    name = inst["instance"]
    ours = json.loads(subprocess.run([a.bin, "diagnose", name, "--max-wall", str(a.max_wall)], check=True,
                                     stdout=subprocess.PIPE).stdout)
    d = json.loads(subprocess.run([a.bin, "export", name], check=True, stdout=subprocess.PIPE).stdout)
    result = {}
    t = threading.Thread(target=lambda: result.update(r=ipopt_diagnosis(d, a)))
    t.start()
    t.join()
    return {"instance": name, "symnlp": dict(status=ours["status"], **ours["diagnosis"]), "ipopt": result["r"]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="target/release/corpus", help="the corpus binary")
    ap.add_argument("--out", required=True, help="JSON-lines results file (appended to)")
    ap.add_argument("--filter", help="comma-separated substrings of instance names")
    ap.add_argument("--kind", choices=["ocp", "cute"])
    ap.add_argument("--max-n", type=int)
    ap.add_argument("--max-wall", type=float, default=600.0, help="wall-time cap per solve (both solvers)")
    ap.add_argument("--print-level", type=int, default=0)
    ap.add_argument("--fresh", action="store_true", help="truncate --out first")
    ap.add_argument("--diagnose", action="store_true",
                    help="write iteration summaries of both solvers (regularised and tiny steps) instead of results")
    a = ap.parse_args()
    sys.setrecursionlimit(1_000_000)
    threading.stack_size(512 * 1024 * 1024)
    if a.fresh and os.path.exists(a.out):
        os.remove(a.out)
    done = set()
    if os.path.exists(a.out):
        with open(a.out) as fh:
            done = {json.loads(l)["instance"] for l in fh if l.strip()}
    for inst in listing(a):
        name = inst["instance"]
        if name in done:
            continue
        print(f"== {name} (n {inst['n']}, m {inst['m']})", file=sys.stderr)
        if a.diagnose:
            with open(a.out, "a") as fh:
                fh.write(json.dumps(diagnose(inst, a)) + "\n")
            continue
        cmd = [a.bin, "export", name, "--solve", "--max-wall", str(a.max_wall)]
        d = json.loads(subprocess.run(cmd, check=True, stdout=subprocess.PIPE).stdout)
        line = {"instance": name, "symnlp": d["symnlp"], "ipopt": ipopt_on(d, a)}
        with open(a.out, "a") as fh:
            fh.write(json.dumps(line) + "\n")


if __name__ == "__main__":
    main()
