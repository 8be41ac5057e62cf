"""The COPS 3.0 Goddard rocket exactly as COPS writes it, solved by CasADi + IPOPT.

Variables h, v, m, T at nh + 1 nodes and the step; trapezoidal rule; objective -h[nh];
boundary values as equality rows (h[0] = 1, v[0] = 0, m[0] = 1, m[nh] = 0.6) with those
entries' simple bounds dropped; starting point h = 1, v = t(1 - t), m linear from 1 to
0.6, T = T_max/2, step = 1/nh. CasADi's defaults (detect_simple_bounds off, so the rows
stay rows). Prints one JSON line per size: IPOPT's status, iterations and objective.

    python3 benches/reference/cops_rocket_rows.py [400 1600 6000]

corpus family `rocket_rows_trap` (corpus/src/ocp/cops.rs) is the same problem in symnlp.
"""
import json
import sys

import casadi as ca


def solve(nh):
    h0, v0, m0, g0 = 1.0, 0.0, 1.0, 1.0
    tc, hc, vc, mc = 3.5, 500.0, 620.0, 0.6
    c = 0.5 * (g0 * h0) ** 0.5
    mf, dc, tmax = mc * m0, 0.5 * vc * m0 / g0, tc * g0 * m0
    h, v, m, T = (ca.SX.sym(s, nh + 1) for s in "hvmT")
    step = ca.SX.sym("step")
    inf = ca.inf
    lb = [1.0] * (nh + 1) + [0.0] * (nh + 1) + [mf] * (nh + 1) + [0.0] * (nh + 1) + [0.0]
    ub = [inf] * (nh + 1) + [inf] * (nh + 1) + [m0] * (nh + 1) + [tmax] * (nh + 1) + [inf]
    n1 = nh + 1
    for k in (0, n1, 2 * n1, 2 * n1 + nh):  # h[0], v[0], m[0], m[nh]: bounds dropped
        lb[k], ub[k] = -inf, inf
    s = [i / nh for i in range(nh + 1)]
    x0 = [1.0] * n1 + [t * (1 - t) for t in s] + [(mf - m0) * t + m0 for t in s]
    x0 += [tmax / 2] * n1 + [1.0 / nh]

    def rhs(i):
        drag = dc * v[i] ** 2 * ca.exp(-hc * (h[i] - h0) / h0)
        grav = g0 * (h0 / h[i]) ** 2
        return [v[i], (T[i] - drag - m[i] * grav) / m[i], -T[i] / c]

    g = []
    for i in range(1, nh + 1):
        f0, f1 = rhs(i - 1), rhs(i)
        for xs, a, b in zip((h, v, m), f0, f1):
            g.append(xs[i] - xs[i - 1] - 0.5 * step * (a + b))
    g += [h[0] - h0, v[0] - v0, m[0] - m0, m[nh] - mf]
    x = ca.vertcat(h, v, m, T, step)
    solver = ca.nlpsol("rocket", "ipopt", {"x": x, "f": -h[nh], "g": ca.vertcat(*g)},
                       {"ipopt.print_level": 0, "print_time": 0, "ipopt.tol": 1e-8})
    sol = solver(x0=x0, lbx=lb, ubx=ub, lbg=0, ubg=0)
    st = solver.stats()
    return {"nh": nh, "status": st["return_status"], "iterations": st["iter_count"],
            "objective": float(sol["f"])}


if __name__ == "__main__":
    for nh in [int(a) for a in sys.argv[1:]] or [400, 1600, 6000]:
        print(json.dumps(solve(nh)), flush=True)
