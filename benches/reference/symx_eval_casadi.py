"""CasADi reference for the symbolic build + evaluation benchmark (benches/symx_eval.rs).

Problem: hanging chain (see hanging_chain.py) with N = 1000 links (n = 2002 variables,
m = 1000 constraints).

(a) build: time to
      1. build the SX expressions x, f, g (hanging_chain.build),
      2. grad_f = gradient(f, x)                           (CasADi returns it dense: nnz = n,
                                                           though the x-components are 0),
      3. jac_g  = jacobian(g, x),
      4. hess_L = tril(hessian(sigma*f + lam' g, x))       (sigma scalar, lam m-vector, both symbolic),
      5. create the three SX Functions
            grad_f(x), jac_g(x), hess_L(x, sigma, lam).
    Reported per phase and in total (median over --build-reps runs).

(b) eval: time per evaluation of each Function at the initial guess x0, with
    sigma = 1 and lam_i = (i+1)/N (i = 0..N-1). Inputs are converted to DM once, up front
    (converting a 2002-element numpy array to DM alone costs ~180 us per call, which would
    swamp everything). Reported per Function:
      * internal_us:  RECOMMENDED comparison number. The Function is created with
                      {'record_time': True}; after each plain call F(*dm_inputs) we read
                      F.stats()['t_wall_total'], CasADi's own wall-clock timer around the
                      evaluation (SX virtual machine, no Python involved). Median over
                      --internal-calls calls (repeated --eval-reps times, median of medians);
                      internal_us_min is the fastest single call seen.
      * call_us:      median per call of the plain Python call F(*dm_inputs), timed with
                      timeit (includes Python/SWIG dispatch and creation of the DM output);
      * overhead_us:  the same for a *trivial* Function with the same input signature
                      (returns a constant scalar 0): the Python/CasADi call overhead.
                      call_us - overhead_us is a second estimate of pure evaluation
                      (it still contains allocation/copy of the nnz-sized output);
      * map_us:       F.map('m', 'serial', K, [all inputs], [output], {}) — K serial
                      evaluations with shared (non-repeated) inputs and the output summed over
                      the K evaluations — timed as one call and divided by K; a third
                      estimate (contains one extra nnz-vector add per evaluation).
      * call_numpy_us: plain call with numpy inputs (converted on every call), for reference.
    Every timeit number is the median of --eval-reps repetitions.

Also prints: casadi version, nnz of each output, the number of SX VM instructions of each
Function, and value checksums (sum, sum of |.|, 2-norm of the nonzeros) so the Rust side can check
that it evaluates the identical quantities.

Output: one JSON object on stdout.
Run:    python3 benches/reference/symx_eval_casadi.py [--links 1000] > results/symx_eval_casadi.json
"""
import argparse
import json
import os
import platform
import statistics
import sys
import time

import casadi as ca
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hanging_chain  # noqa: E402
from eval_timing import internal_times, nz_stats, time_call  # noqa: E402


def build_all(N):
    t = {}
    t0 = time.perf_counter()
    p = hanging_chain.build(N)
    x, f, g = p["x"], p["f"], p["g"]
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
    t["expr"] = t1 - t0
    t["grad_f"] = t2 - t1
    t["jac_g"] = t3 - t2
    t["hess_L"] = t4 - t3
    t["functions"] = t5 - t4
    t["total"] = t5 - t0
    exprs = {"grad_f": ([x], grad_f), "jac_g": ([x], jac_g), "hess_L": ([x, sigma, lam], hess_l)}
    return p, (F_grad, F_jac, F_hess), (x, sigma, lam), t, exprs


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--links", type=int, default=1000)
    ap.add_argument("--build-reps", type=int, default=5)
    ap.add_argument("--eval-reps", type=int, default=7)
    ap.add_argument("--map-k", type=int, default=100)
    ap.add_argument("--internal-calls", type=int, default=300)
    args = ap.parse_args()
    N = args.links

    builds = []
    for _ in range(args.build_reps):
        p, funcs, syms, t, exprs = build_all(N)
        builds.append(t)
    build_median_s = {k: statistics.median(b[k] for b in builds) for k in builds[0]}

    F_grad, F_jac, F_hess = funcs
    x0 = p["x0"]
    sigma0 = 1.0
    lam0 = np.array([(i + 1) / N for i in range(N)])
    np_inputs = {"grad_f": [x0], "jac_g": [x0], "hess_L": [x0, sigma0, lam0]}
    func = {"grad_f": F_grad, "jac_g": F_jac, "hess_L": F_hess}

    # identical Functions that record CasADi-internal timings (created outside the build timing)
    REC = {
        k: ca.Function(k + "_timed", ins_, [e], {"record_time": True}) for k, (ins_, e) in exprs.items()
    }

    # trivial Functions with the same input signatures
    xs, ss, ls = syms
    triv1 = ca.Function("triv1", [xs], [ca.SX(0)])
    triv3 = ca.Function("triv3", [xs, ss, ls], [ca.SX(0)])
    triv = {"grad_f": triv1, "jac_g": triv1, "hess_L": triv3}

    out = {
        "benchmark": "symx_eval",
        "problem": "hanging_chain",
        "links": N,
        "n": hanging_chain.n_vars(N),
        "m": N,
        "casadi_version": ca.__version__,
        "python": platform.python_version(),
        "eval_point": "x = initial guess, sigma = 1, lam_i = (i+1)/N",
        "hessian": "tril(hessian(sigma*f + dot(lam, g), x)) (lower triangle incl. diagonal)",
        "recommended_eval_number": "internal_us (CasADi record_time t_wall_total per call)",
        "build_reps": args.build_reps,
        "eval_reps": args.eval_reps,
        "internal_calls": args.internal_calls,
        "map_k": args.map_k,
        "build_s_median": build_median_s,
        "build_s_all": builds,
        "functions": {},
    }

    for name, F in func.items():
        npin = np_inputs[name]
        ins = [ca.DM(a) for a in npin]
        res = F(*ins)
        # CasADi-internal timing
        internal_med, internal_min, rep_medians = internal_times(
            REC[name], ins, args.eval_reps, args.internal_calls
        )

        call_s, call_samples = time_call(lambda: F(*ins), args.eval_reps)
        T = triv[name]
        ovh_s, _ = time_call(lambda: T(*ins), args.eval_reps)
        np_s, _ = time_call(lambda: F(*npin), max(3, args.eval_reps // 2), target=0.1)
        K = args.map_k
        nin = F.n_in()
        FM = F.map("m", "serial", K, list(range(nin)), [0], {})
        chk = FM(*ins)
        map_ok = float(ca.norm_fro(chk - K * res)) <= 1e-9 * max(1.0, float(ca.norm_fro(K * res)))
        map_s, map_samples = time_call(lambda: FM(*ins), args.eval_reps, target=0.3)
        out["functions"][name] = {
            **nz_stats(res),
            "shape": list(res.shape),
            "n_instructions": int(F.n_instructions()),
            "internal_us": internal_med * 1e6,
            "internal_us_min": internal_min * 1e6,
            "call_us": call_s * 1e6,
            "overhead_us": ovh_s * 1e6,
            "call_minus_overhead_us": (call_s - ovh_s) * 1e6,
            "map_us": map_s / K * 1e6,
            "map_check_ok": map_ok,
            "call_numpy_us": np_s * 1e6,
            "call_us_samples": [s * 1e6 for s in call_samples],
            "map_us_samples": [s / K * 1e6 for s in map_samples],
            "internal_us_rep_medians": [t * 1e6 for t in rep_medians],
        }

    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
