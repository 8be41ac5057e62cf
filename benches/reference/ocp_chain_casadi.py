"""CasADi SX side of the `ocp_chain` group of benches/symx_eval.rs: the quadrotor OCP of
testkit/src/quadrotor_ocp.rs (12 states, 4 controls, N stages, one RK4 step per stage,
multiple shooting), built as SX (the RK4 step inlined at every stage, as SX does), then
grad f, jac g, the lower triangle of the Lagrangian Hessian with symbolic sigma and lambda,
and the three Functions. Prints a JSON line with the median times (ms) over `reps` runs,
checksums of the three functions at the bench's point with sigma = 1, lambda_i = (i+1)/m,
and their evaluation times: CasADi's own `record_time` wall time of single calls (SX
virtual machine, no Python), median over up to 300 calls, median of 7 repetitions (the
statistic of the Rust bench's `per-call median`), with the SX instruction counts.

Run: python3 benches/reference/ocp_chain_casadi.py [N=1000] [reps=3]
     python3 benches/reference/ocp_chain_casadi.py N memory   (one set-up, then exit: for
     peak memory with /usr/bin/time -v; benches/reference/ocp_compare.sh does this)
"""
import json
import os
import sys
import time

import casadi as ca

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from eval_timing import internal_times  # noqa: E402

NX, NU, H = 12, 4, 0.02
MASS, GRAVITY, ARM, YAW_COEF, DRAG = 1.0, 9.81, 0.2, 0.05, 0.1
JX, JY, JZ = 0.01, 0.012, 0.02


def ode(x, u):
    v, e, w = x[3:6], x[6:9], x[9:12]
    thrust = u[0] + u[1] + u[2] + u[3]
    tau = [ARM * (u[1] - u[3]), ARM * (u[2] - u[0]), YAW_COEF * (u[0] - u[1] + u[2] - u[3])]
    sf, cf = ca.sin(e[0]), ca.cos(e[0])
    st, ct, tt = ca.sin(e[1]), ca.cos(e[1]), ca.tan(e[1])
    sp, cp = ca.sin(e[2]), ca.cos(e[2])
    a = thrust / MASS
    return [v[0], v[1], v[2],
            a * (cf * st * cp + sf * sp) - DRAG * v[0],
            a * (cf * st * sp - sf * cp) - DRAG * v[1],
            a * (cf * ct) - GRAVITY - DRAG * v[2],
            w[0] + sf * tt * w[1] + cf * tt * w[2],
            cf * w[1] - sf * w[2],
            sf / ct * w[1] + cf / ct * w[2],
            (tau[0] - (JZ - JY) * w[1] * w[2]) / JX,
            (tau[1] - (JX - JZ) * w[2] * w[0]) / JY,
            (tau[2] - (JY - JX) * w[0] * w[1]) / JZ]


def rk4(x, u):
    add = lambda a, b, s: [ai + s * bi for ai, bi in zip(a, b)]
    k1 = ode(x, u)
    k2 = ode(add(x, k1, H / 2), u)
    k3 = ode(add(x, k2, H / 2), u)
    k4 = ode(add(x, k3, H), u)
    return [x[i] + H / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]) for i in range(NX)]


def build(n):
    w = ca.SX.sym("w", n * (NX + NU) + NX)
    xs = lambda k: [w[k * (NX + NU) + i] for i in range(NX)]
    us = lambda k: [w[k * (NX + NU) + NX + i] for i in range(NU)]
    xr = [1.0 if i < 3 else 0.0 for i in range(NX)]
    dev = lambda x: ca.sum1(ca.vertcat(*[(a - b) ** 2 for a, b in zip(x, xr)]))
    f, g = 0, []
    for k in range(n):
        nxt = rk4(xs(k), us(k))
        g += [a - b for a, b in zip(nxt, xs(k + 1))]
        f += dev(xs(k)) + 0.1 * ca.sum1(ca.vertcat(*[u ** 2 for u in us(k)]))
    f += 10 * dev(xs(n))
    g += xs(0)
    return w, f, ca.vertcat(*g)


def point(n):
    return [GRAVITY * MASS / 4 + 0.01 * (i % 7) if i % (NX + NU) >= NX
            else 0.05 * ((i * 13 % 17) - 8.0) / 8.0 for i in range(n * (NX + NU) + NX)]


def run(n):
    t = [time.perf_counter()]
    w, f, g = build(n)
    t.append(time.perf_counter())
    grad = ca.gradient(f, w)
    t.append(time.perf_counter())
    jac = ca.jacobian(g, w)
    t.append(time.perf_counter())
    sigma = ca.SX.sym("sigma")
    lam = ca.SX.sym("lambda", g.numel())
    hess = ca.tril(ca.hessian(sigma * f + ca.dot(lam, g), w)[0])
    t.append(time.perf_counter())
    fg = ca.Function("grad_f", [w], [grad])
    fj = ca.Function("jac_g", [w], [jac])
    fh = ca.Function("hess_L", [w, sigma, lam], [hess])
    t.append(time.perf_counter())
    return [1e3 * (b - a) for a, b in zip(t, t[1:])], (fg, fj, fh, g.numel())


def eval_times(fns, ins):
    """Per-call internal times (us) and instruction counts of the three functions."""
    out = {}
    for name, f in fns.items():
        timed = ca.Function(name + "_timed", f.sx_in(), f.call(f.sx_in()), {"record_time": True})
        args = ins[: f.n_in()]
        t = time.perf_counter()
        timed(*args)
        calls = max(10, min(300, int(0.3 / max(time.perf_counter() - t, 1e-9))))
        med, mn, _ = internal_times(timed, args, 7, calls)
        out[name] = {"internal_us": med * 1e6, "internal_us_min": mn * 1e6,
                     "instructions": f.n_instructions(), "work": f.sz_w()}
    return out


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    if len(sys.argv) > 2 and sys.argv[2] == "memory":
        run(n)
        sys.exit(0)
    reps = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    runs = [run(n) for _ in range(reps)]
    med = lambda xs: sorted(xs)[len(xs) // 2]
    phases = ["build", "grad_f", "jac_g", "hess_L", "functions"]
    times = {p: med([r[0][k] for r in runs]) for k, p in enumerate(phases)}
    times["total"] = med([sum(r[0]) for r in runs])
    fg, fj, fh, m = runs[-1][1]
    x = point(n)
    lam = [(i + 1) / m for i in range(m)]
    sums = {
        "grad_f": float(ca.sum1(fg(x))),
        "jac_g": float(ca.sum1(ca.sum2(fj(x)))),
        "hess_L": float(ca.sum1(ca.sum2(fh(x, 1.0, lam)))),
    }
    ins = [ca.DM(x), ca.DM(1.0), ca.DM(lam)]
    evals = eval_times({"grad_f": fg, "jac_g": fj, "hess_L": fh}, ins)
    print(json.dumps({"N": n, "reps": reps, "median_ms": times, "checksum": sums,
                      "hess_nnz": fh.sparsity_out(0).nnz(), "eval": evals}))
