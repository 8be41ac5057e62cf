"""IPOPT's limited-memory mode on the Hock–Schittkowski suite (reference for
tests/lbfgs_hs.rs).

The problems are those of hs_casadi.py (same formulations, bounds and starting points as
testkit/src/hs/problems.rs). IPOPT options: tol 1e-8, hessian_approximation limited-memory
(IPOPT's defaults otherwise: BFGS, limited_memory_max_history 6, initialization
scalar1), everything else default.

Usage:
    python3 benches/reference/hs_lbfgs_ipopt.py [name ...] \
        > benches/reference/results/hs_lbfgs_ipopt.jsonl

Prints one JSON object per line:
    {"name", "status", "success", "iterations", "objective", "f_star", "seconds"}
with success = (status == "Solve_Succeeded").

    python3 benches/reference/hs_lbfgs_ipopt.py --compare OURS.jsonl IPOPT.jsonl

prints the Markdown table of docs/solvers.md ("Limited-memory Hessian") from the JSON
lines of `cargo test --release -p nlp --test lbfgs_hs -- --ignored --nocapture hs_lbfgs_summary`
and of this script: iterations per problem, their ratio, and the geometric mean over
the problems both solve.
"""
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hs_casadi  # noqa: E402
from hs_casadi import PROBLEMS  # noqa: E402


def solve(name):
    r = hs_casadi.solve(name, {"ipopt.hessian_approximation": "limited-memory"})
    r["success"] = r["status"] == "Solve_Succeeded"
    return r


def compare(ours_path, ipopt_path):
    def load(path):
        with open(path) as f:
            return {r["name"]: r for r in (json.loads(line) for line in f if line.startswith("{"))}

    ours, ipopt = load(ours_path), load(ipopt_path)
    print("| problem | symnlp status | iter | IPOPT status | iter | ratio |")
    print("|---|---|---:|---|---:|---:|")
    logs = []
    solved_o = solved_i = 0
    for name in sorted(ours):
        o, i = ours[name], ipopt[name]
        ok_o = o["status"] == "SolveSucceeded" and o.get("matches") is not None
        ok_i = i["success"]
        solved_o += ok_o
        solved_i += ok_i
        ratio = ""
        if ok_o and ok_i:
            r = o["iterations"] / i["iterations"]
            logs.append(math.log(r))
            ratio = f"{r:.2f}"
        status_o = o["status"] + ("" if ok_o or o["status"] != "SolveSucceeded" else " (other point)")
        print(f"| {name} | {status_o} | {o.get('iterations', '–')} | {i['status']} | {i['iterations']} | {ratio} |")
    geo = math.exp(sum(logs) / len(logs))
    worse = sum(1 for v in logs if v > math.log(1.5))
    print()
    print(f"solved: symnlp {solved_o}/{len(ours)}, IPOPT {solved_i}/{len(ipopt)}; "
          f"geometric mean of iteration ratios over the {len(logs)} both solve: {geo:.3f}; "
          f"ratio > 1.5 on {worse}")


def main():
    if sys.argv[1:2] == ["--compare"]:
        compare(sys.argv[2], sys.argv[3])
        return
    names = sys.argv[1:] or sorted(PROBLEMS)
    for name in names:
        print(json.dumps(solve(name)), flush=True)


if __name__ == "__main__":
    main()
