"""CasADi reference for the gap-crossing group of the symbolic build + evaluation benchmark
(benches/symx_eval.rs, `symx_eval_gap`).

Problem: the crawl (scheduled) formulation of the gap-crossing planner on the default
scenario (default gap, n_step 60), exactly as symnlp builds it: read from the JSON dump of
`models/gap_crossing/examples/export.rs` (variables with bounds and x0, constraint rows and
objective printed by symx) and parsed into CasADi SX with the parser of
gap_crossing_casadi.py (names -> x[i] of one SX vector, shared subexpressions `@k` kept
shared). The dump carries symnlp's f(x0) and g(x0); the parsed expressions are checked
against them.

(a) build: time to
      1. parse the printed objective and constraints into SX (the counterpart of symnlp's
         model build; Python, listed for completeness),
      2. grad_f = gradient(f, x)                         (dense),
      3. jac_g  = jacobian(g, x),
      4. hess_L = tril(hessian(sigma*f + lam' g, x))     (sigma scalar, lam m-vector, symbolic),
      5. create the three SX Functions grad_f(x), jac_g(x), hess_L(x, sigma, lam).
    Median per phase over --build-reps runs.

(b) eval: at x0 with sigma = 1 and lam_i = (i+1)/m. `internal_us` is the comparison number
    (the same statistic as benches/symx_eval.rs's `per-call median`): the Function is
    created with {'record_time': True} and after each call F(*dm_inputs) we read
    stats()['t_wall_total'] (CasADi's own timer around the SX virtual machine, no Python);
    median over --internal-calls calls, median of --eval-reps repetitions. `call_us` is the
    plain Python call (timeit, median of --eval-reps), `overhead_us` that of a trivial
    Function with the same inputs.

Also prints nnz, SX instruction counts and value checksums (sum, sum |.|, 2-norm of the
nonzeros), which must match what `cargo bench --bench symx_eval -- gap` prints.

Run:
  cargo build --release -p gap_crossing --example export
  python3 benches/reference/symx_eval_gap_casadi.py --export-bin target/release/examples/export \\
      > benches/reference/results/symx_eval_gap_casadi.json
  (or --dump FILE with a dump written by the example; default scenario, n_step 60)
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import threading
import time

import casadi as ca
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from eval_timing import internal_times, nz_stats, time_call  # noqa: E402
from gap_crossing_casadi import Parser  # noqa: E402


def build_all(d):
    t = {}
    n = d["n"]
    t0 = time.perf_counter()
    x = ca.SX.sym("x", n)
    p = Parser({v["name"]: x[i] for i, v in enumerate(d["variables"])})
    f = p.parse(d["objective"])
    f = ca.SX(f) if not isinstance(f, ca.SX) else f
    g = ca.vertcat(*[p.parse(c["expr"]) for c in d["constraints"]])
    t1 = time.perf_counter()
    grad_f = ca.gradient(f, x)
    t2 = time.perf_counter()
    jac_g = ca.jacobian(g, x)
    t3 = time.perf_counter()
    sigma = ca.SX.sym("sigma")
    lam = ca.SX.sym("lam", g.numel())
    lag = sigma * f + ca.dot(lam, g)
    H, _ = ca.hessian(lag, x)
    hess_l = ca.tril(H)
    t4 = time.perf_counter()
    F_grad = ca.Function("grad_f", [x], [grad_f])
    F_jac = ca.Function("jac_g", [x], [jac_g])
    F_hess = ca.Function("hess_L", [x, sigma, lam], [hess_l])
    t5 = time.perf_counter()
    t["parse"] = t1 - t0
    t["grad_f"] = t2 - t1
    t["jac_g"] = t3 - t2
    t["hess_L"] = t4 - t3
    t["functions"] = t5 - t4
    t["total"] = t5 - t0
    t["total_without_parse"] = t5 - t1
    exprs = {"grad_f": ([x], grad_f), "jac_g": ([x], jac_g), "hess_L": ([x, sigma, lam], hess_l)}
    return (x, f, g), (F_grad, F_jac, F_hess), (x, sigma, lam), t, exprs


def run(d, args):
    builds = []
    for _ in range(args.build_reps):
        (x, f, g), funcs, syms, t, exprs = build_all(d)
        builds.append(t)
        print("build " + " ".join(f"{k} {v * 1e3:.1f} ms" for k, v in t.items()), file=sys.stderr)
    build_median_s = {k: statistics.median(b[k] for b in builds) for k in builds[0]}

    n, m = d["n"], d["m"]
    x0 = np.array([v["x0"] for v in d["variables"]])
    fg = ca.Function("fg", [x], [f, g])
    f0, g0 = fg(x0)
    f_err = abs(float(f0) - d["f0"])
    g_err = float(np.max(np.abs(g0.full().ravel() - np.array([c["g0"] for c in d["constraints"]]))))

    lam0 = np.array([(i + 1) / m for i in range(m)])
    np_inputs = {"grad_f": [x0], "jac_g": [x0], "hess_L": [x0, 1.0, lam0]}
    func = dict(zip(["grad_f", "jac_g", "hess_L"], funcs))
    rec_f = {k: ca.Function(k + "_timed", i, [e], {"record_time": True}) for k, (i, e) in exprs.items()}
    xs, ss, ls = syms
    triv1 = ca.Function("triv1", [xs], [ca.SX(0)])
    triv3 = ca.Function("triv3", [xs, ss, ls], [ca.SX(0)])
    triv = {"grad_f": triv1, "jac_g": triv1, "hess_L": triv3}

    out = {
        "benchmark": "symx_eval_gap",
        "problem": d.get("description"),
        "n": n,
        "m": m,
        "casadi_version": ca.__version__,
        "python": platform.python_version(),
        "eval_point": "x = dumped initial point, sigma = 1, lam_i = (i+1)/m",
        "hessian": "tril(hessian(sigma*f + dot(lam, g), x)) (lower triangle incl. diagonal)",
        "recommended_eval_number": "internal_us (CasADi record_time t_wall_total per call)",
        "f0_error": f_err,
        "g0_error": g_err,
        "build_reps": args.build_reps,
        "eval_reps": args.eval_reps,
        "internal_calls": args.internal_calls,
        "build_s_median": build_median_s,
        "build_s_all": builds,
        "functions": {},
    }
    for name, F in func.items():
        ins = [ca.DM(a) for a in np_inputs[name]]
        res = F(*ins)
        internal_med, internal_min, rep_medians = internal_times(
            rec_f[name], ins, args.eval_reps, args.internal_calls
        )
        call_s, _ = time_call(lambda: F(*ins), args.eval_reps)
        T = triv[name]
        ovh_s, _ = time_call(lambda: T(*ins), args.eval_reps)
        out["functions"][name] = {
            **nz_stats(res),
            "shape": list(res.shape),
            "n_instructions": int(F.n_instructions()),
            "internal_us": internal_med * 1e6,
            "internal_us_min": internal_min * 1e6,
            "call_us": call_s * 1e6,
            "overhead_us": ovh_s * 1e6,
            "internal_us_rep_medians": [t * 1e6 for t in rep_medians],
        }
        r = out["functions"][name]
        print(f"{name:7} nnz {r['nnz']:6}  instructions {r['n_instructions']:6}  sum {r['sum']:.16e}  "
              f"norm2 {r['norm2']:.16e}  internal median {r['internal_us']:.3f} us", file=sys.stderr)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dump", help="dump JSON written by the export example")
    ap.add_argument("--export-bin", help="path of the export example binary (target/release/examples/export)")
    ap.add_argument("--set", action="append", default=[], help="scenario override for the export binary")
    ap.add_argument("--build-reps", type=int, default=5)
    ap.add_argument("--eval-reps", type=int, default=7)
    ap.add_argument("--internal-calls", type=int, default=300)
    args = ap.parse_args()
    if args.dump:
        with open(args.dump) as fh:
            d = json.load(fh)
    elif args.export_bin:
        cmd = [args.export_bin]
        for s in args.set:
            cmd += ["--set", s]
        print("running " + " ".join(cmd), file=sys.stderr)
        d = json.loads(subprocess.run(cmd, check=True, stdout=subprocess.PIPE).stdout)
    else:
        ap.error("give --dump or --export-bin")

    result = {}

    def work():
        result["out"] = run(d, args)

    # Deeply nested sums: parse recursively on a thread with a large stack.
    sys.setrecursionlimit(1_000_000)
    threading.stack_size(512 * 1024 * 1024)
    t = threading.Thread(target=work)
    t.start()
    t.join()
    if "out" not in result:
        sys.exit(1)
    result["out"]["overrides"] = args.set
    print(json.dumps(result["out"], indent=1))


if __name__ == "__main__":
    main()
