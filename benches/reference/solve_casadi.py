"""CasADi + IPOPT reference solves for the hanging chain and Van der Pol OCP.

Problems: see hanging_chain.py and ocp.py (exact formulations in their docstrings).
Sizes (about 1e2, 1e3, 1e4, 1e5 variables):
    hanging_chain: N = 50, 500, 5000, 50000 links     -> n = 2(N+1) = 102, 1002, 10002, 100002
    ocp (VdP):     N = 33, 333, 3333, 33333 intervals -> n = 3N+2   = 101, 1001, 10001, 100001

Solver: nlpsol('S', 'ipopt', {x, f, g}) on SX expressions, exact Hessian (CasADi default),
IPOPT options: tol = 1e-8, print_level = 0, sb = yes; CasADi options print_time = false,
record_time = true (needed for stats()['t_wall_total'] when print_time is false),
max_wall_time = --cap seconds (default 180: a solve hitting it is reported with
"capped": true). Each size runs in a child process that is killed after cap*reps + 60 s
(IPOPT only checks max_wall_time between iterations, and a single MUMPS factorization can
run far longer) and whose address space is limited to --mem-gb (8) GiB; such a size is
reported as return_status "killed_by_harness_timeout" / "child_failed". Everything else is IPOPT's default (MUMPS linear solver).
Started from the problem's stated initial guess x0, with lbx/ubx/lbg/ubg from the problem.

Per (problem, N), one JSON line with:
    build_s       time to build the SX expressions (Python loops, incl. bounds/x0 arrays)
    construct_s   time of the nlpsol(...) call (CasADi derives grad/jac/Hessian and creates
                  the SX Functions here) -- NOT included in solve_s
    solve_s       median wall time of the S(x0=..., lbx=..., ...) call, over `reps` solves
                  with the same solver object (solve_s_all has every sample)
    t_wall_total  S.stats()['t_wall_total'] of the median solve (CasADi's own wall timer)
    iter_count, return_status, success, f (objective), max |g|, and CasADi's per-callback
    wall times / call counts (t_wall_nlp_*, n_call_nlp_*) from the last solve.

Run:  python3 benches/reference/solve_casadi.py > benches/reference/results/solve_casadi.jsonl
      (--problems hanging_chain,ocp --sizes 2,3,4,5 --reps-small 5 --reps-large 1 --cap 180)
"""
import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time

import casadi as ca
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hanging_chain  # noqa: E402
import ocp  # noqa: E402

PROBLEMS = {
    "hanging_chain": (hanging_chain, {2: 50, 3: 500, 4: 5000, 5: 50000}),
    "ocp": (ocp, {2: 33, 3: 333, 4: 3333, 5: 33333}),
}


def run(name, N, reps, cap):
    mod = PROBLEMS[name][0]
    t0 = time.perf_counter()
    p = mod.build(N)
    t1 = time.perf_counter()
    opts = {
        "print_time": False,
        # with print_time=False, CasADi 3.8.2 only reports t_wall_total/t_proc_total in
        # S.stats() when record_time=True (the per-callback t_wall_nlp_* are always there)
        "record_time": True,
        "ipopt.print_level": 0,
        "ipopt.sb": "yes",
        "ipopt.tol": 1e-8,
        "ipopt.max_wall_time": float(cap),
    }
    S = ca.nlpsol("S", "ipopt", {"x": p["x"], "f": p["f"], "g": p["g"]}, opts)
    t2 = time.perf_counter()
    args = dict(x0=p["x0"], lbx=p["lbx"], ubx=p["ubx"], lbg=p["lbg"], ubg=p["ubg"])
    samples, stats_all, sol = [], [], None
    for _ in range(reps):
        ts = time.perf_counter()
        sol = S(**args)
        te = time.perf_counter()
        samples.append(te - ts)
        stats_all.append(S.stats())
        if stats_all[-1]["return_status"] == "Maximum_WallTime_Exceeded":
            break
    med = statistics.median(samples)
    imed = min(range(len(samples)), key=lambda i: abs(samples[i] - med))
    st = stats_all[-1]
    g = np.asarray(sol["g"]).ravel()
    out = {
        "problem": name,
        "N": N,
        "n": int(p["x"].numel()),
        "m": int(p["g"].numel()),
        "casadi_version": ca.__version__,
        "build_s": t1 - t0,
        "construct_s": t2 - t1,
        "reps": len(samples),
        "solve_s": med,
        "solve_s_all": samples,
        "t_wall_total": stats_all[imed]["t_wall_total"],
        "t_wall_total_all": [s["t_wall_total"] for s in stats_all],
        "iter_count": int(st["iter_count"]),
        "return_status": st["return_status"],
        "success": bool(st["success"]),
        "capped": st["return_status"] == "Maximum_WallTime_Exceeded",
        "f": float(sol["f"]),
        "max_abs_g": float(np.max(np.abs(g))) if g.size else 0.0,
    }
    for k in sorted(st):
        if k.startswith("t_wall_nlp") or k.startswith("n_call_nlp"):
            out[k] = st[k]
    return out


def run_capped(name, N, reps, cap, mem_gb):
    """Run one (problem, N) in a child process with a hard wall-clock cap.

    IPOPT's max_wall_time is only checked between iterations; a single MUMPS factorization
    can take far longer (see README: delayed pivots on the hanging chain), so the child is
    killed after cap * reps + 60 s, and its address space is limited to mem_gb GiB.
    """
    cmd = [sys.executable, os.path.abspath(__file__), "--one", name, str(N), str(reps), str(cap)]

    def limit():
        lim = int(mem_gb * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (lim, lim))

    hard = cap * reps + 60
    t0 = time.perf_counter()
    try:
        cp = subprocess.run(cmd, capture_output=True, text=True, timeout=hard, preexec_fn=limit)
    except subprocess.TimeoutExpired:
        return {"problem": name, "N": N, "n": PROBLEMS[name][0].n_vars(N), "capped": True,
                "return_status": "killed_by_harness_timeout", "killed_after_s": time.perf_counter() - t0,
                "note": "no solve finished within the hard cap (IPOPT max_wall_time is only checked "
                        "between iterations)"}
    lines = [l for l in cp.stdout.splitlines() if l.startswith("{")]
    if cp.returncode != 0 or not lines:
        return {"problem": name, "N": N, "n": PROBLEMS[name][0].n_vars(N), "capped": True,
                "return_status": "child_failed", "returncode": cp.returncode,
                "stderr_tail": cp.stderr[-2000:]}
    return json.loads(lines[-1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--problems", default="hanging_chain,ocp")
    ap.add_argument("--sizes", default="2,3,4,5", help="log10 of the variable count")
    ap.add_argument("--reps-small", type=int, default=5, help="solves per size for 1e2..1e3")
    ap.add_argument("--reps-mid", type=int, default=3, help="solves per size for 1e4")
    ap.add_argument("--reps-large", type=int, default=1, help="solves per size for >= 1e5")
    ap.add_argument("--cap", type=float, default=180.0, help="IPOPT max_wall_time per solve [s]")
    ap.add_argument("--mem-gb", type=float, default=8.0, help="address-space limit of each child")
    ap.add_argument("--one", nargs=4, metavar=("PROBLEM", "N", "REPS", "CAP"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        name, N, reps, cap = args.one
        res = run(name, int(N), int(reps), float(cap))
        res["python"] = platform.python_version()
        print(json.dumps(res), flush=True)
        return
    for name in args.problems.split(","):
        for e in [int(s) for s in args.sizes.split(",")]:
            reps = args.reps_small if e <= 3 else (args.reps_mid if e == 4 else args.reps_large)
            print(json.dumps(run_capped(name, PROBLEMS[name][1][e], reps, args.cap, args.mem_gb)), flush=True)


if __name__ == "__main__":
    main()
