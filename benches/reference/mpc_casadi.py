"""The closed loops of examples/mpc_*.rs run with CasADi 3.8.2 on the identical
transcription (variables X (nx x (N+1), column by column) then U; rows: initial state
X0 - x0 (the parameter), then continuity X_{k+1} - RK4(X_k, U_k); the stage cost
integrated by the same RK4 step as a quadrature state, plus the terminal cost), the same
nominal plant (one RK4 step per sampling period), the same shift of the previous
solution (stage k <- stage k+1, the last stage duplicated; multipliers moved with their
rows) and the same warm start.

Solvers: IPOPT (the first step cold; then warm_start_init_point with symnlp's
warm_start_* defaults and mu_init 1e-6, as nlp::Ipm::solve_warm), sqpmethod + qrqp, and
RTI (sqpmethod with max_iter 1 + qrqp; its steps report success = false whenever one
iteration does not converge, which is RTI by design). Latency: wall time of the shift and the solver
call, measured with time.perf_counter.

Usage: python3 benches/reference/mpc_casadi.py [cart_pole|car] [ipopt,sqp,rti]
       (prints one JSON line per solver: closed-loop cost, statuses, iterations, latencies)
"""
import json
import math
import sys
import time

import casadi as ca
import numpy as np

from ocp_transcription import rk_integrate

RK4 = ([[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1, 0]], [1 / 6, 1 / 3, 1 / 3, 1 / 6])


def cart_pole():
    m1, m2, l, g = 1.0, 0.3, 0.5, 9.81

    def f(x, u):
        s, c = ca.sin(x[1]), ca.cos(x[1])
        ddq1 = (l * m2 * s * x[3] ** 2 + u[0] + m2 * g * c * s) / (m1 + m2 * (1.0 - c ** 2))
        ddq2 = -(l * m2 * c * s * x[3] ** 2 + u[0] * c + (m1 + m2) * g * s) / (
            l * m1 + l * m2 * (1.0 - c ** 2))
        return [x[2], x[3], ddq1, ddq2]

    def stage(x, u):
        return (5.0 * x[0] ** 2 + 10.0 * (x[1] - math.pi) ** 2 + 0.1 * (x[2] ** 2 + x[3] ** 2)
                + 0.01 * u[0] ** 2)

    inf = math.inf
    return {
        "nx": 4, "nu": 1, "N": 40, "dt": 0.05, "steps": 100,
        "f": f, "l": stage, "phi": lambda x: 100.0 * stage(x, [0.0]),
        "x_lb": [-2.0, -inf, -inf, -inf], "x_ub": [2.0, inf, inf, inf],
        "u_lb": [-20.0], "u_ub": [20.0],
        "x_init": [0.0] * 4,
        "guess_end": [0.0, math.pi, 0.0, 0.0],
    }


def car():
    L, target = 1.0, [5.0, 2.0]

    def f(x, u):
        return [x[3] * ca.cos(x[2]), x[3] * ca.sin(x[2]), x[3] * ca.tan(u[1]) / L, u[0]]

    def stage(x, u):
        return ((x[0] - target[0]) ** 2 + (x[1] - target[1]) ** 2 + x[2] ** 2 + 0.1 * x[3] ** 2
                + 0.1 * (u[0] ** 2 + u[1] ** 2))

    inf = math.inf
    return {
        "nx": 4, "nu": 2, "N": 30, "dt": 0.1, "steps": 80,
        "f": f, "l": stage, "phi": lambda x: 10.0 * stage(x, [0.0, 0.0]),
        "x_lb": [-inf, -inf, -inf, -1.0], "x_ub": [inf, inf, inf, 3.0],
        "u_lb": [-2.0, -0.6], "u_ub": [2.0, 0.6],
        "x_init": [0.0] * 4, "guess_end": None, "u_guess": [0.0, 0.0],
    }


def quadrotor():
    from ocp_examples import QR, quadrotor as qr
    hover = QR["m"] * QR["g"] / 4

    def stage(x, u):
        t = [1.0, 1.0, 1.0]
        l = 0
        for i in range(3):
            l = l + 10.0 * (x[i] - t[i]) ** 2 + x[3 + i] ** 2 + x[6 + i] ** 2 + 0.1 * x[9 + i] ** 2
        for j in range(4):
            l = l + 0.1 * (u[j] - hover) ** 2
        return l

    inf, tilt = math.inf, math.pi / 4
    return {
        "nx": 12, "nu": 4, "N": 20, "dt": 0.1, "steps": 50,
        "f": qr()["f"], "l": stage, "phi": lambda x: 10.0 * stage(x, [hover] * 4),
        "x_lb": [-inf] * 6 + [-tilt, -tilt, -inf] + [-inf] * 3,
        "x_ub": [inf] * 6 + [tilt, tilt, inf] + [inf] * 3,
        "u_lb": [0.0] * 4, "u_ub": [2.5] * 4,
        "x_init": [0.0] * 12, "guess_end": None, "u_guess": [hover] * 4,
    }


PROBLEMS = {"cart_pole": cart_pole, "car": car, "quadrotor": quadrotor}


def build(P):
    nx, nu, N, dt = P["nx"], P["nu"], P["N"], P["dt"]
    X = ca.SX.sym("X", nx, N + 1)
    U = ca.SX.sym("U", nu, N)
    p = ca.SX.sym("x0", nx)
    col = lambda M, k: [M[i, k] for i in range(M.shape[0])]
    g = [X[i, 0] - p[i] for i in range(nx)]
    J = 0
    A, b = RK4
    for k in range(N):
        uk = col(U, k)

        def rhs(z):
            xs = [z[i] for i in range(nx)]
            return ca.vertcat(*(list(P["f"](xs, uk)) + [P["l"](xs, uk)]))

        z = rk_integrate(rhs, ca.vertcat(*(col(X, k) + [0])), dt, A, b, 1)
        J = J + z[nx]
        g += [X[i, k + 1] - z[i] for i in range(nx)]
    J = J + P["phi"](col(X, N))
    w, lbw, ubw, w0 = [], [], [], []
    T = N * dt
    for k in range(N + 1):
        s = min(max(k * T / N / T, 0.0), 1.0)
        for i in range(nx):
            w.append(X[i, k]); lbw.append(P["x_lb"][i]); ubw.append(P["x_ub"][i])
            # symnlp's guess: linear from the start to guess_end, else 0.
            a, e = (P["x_init"][i], P["guess_end"][i]) if P["guess_end"] else (0.0, 0.0)
            w0.append(a + s * (e - a))
    for k in range(N):
        for j in range(nu):
            w.append(U[j, k]); lbw.append(P["u_lb"][j]); ubw.append(P["u_ub"][j])
            w0.append(P.get("u_guess", [0.0] * nu)[j])
    nlp = {"x": ca.vertcat(*w), "f": J, "g": ca.vertcat(*g), "p": p}
    # The plant: one RK4 step of the dynamics.
    xs, us = ca.SX.sym("x", nx), ca.SX.sym("u", nu)
    xn = rk_integrate(lambda z: ca.vertcat(*P["f"]([z[i] for i in range(nx)], [us[j] for j in range(nu)])),
                      xs, dt, A, b, 1)
    plant = ca.Function("plant", [xs, us], [xn])
    cost = ca.Function("l", [xs, us], [P["l"]([xs[i] for i in range(nx)], [us[j] for j in range(nu)])])
    return nlp, np.array(lbw), np.array(ubw), np.array(w0), plant, cost


def shift(v, P, rows=False):
    nx, nu, N = P["nx"], P["nu"], P["N"]
    v = v.copy()
    if rows:  # g = [initial state (nx), continuity (N nx)]
        for k in range(N - 1):
            v[nx + k * nx: nx + (k + 1) * nx] = v[nx + (k + 1) * nx: nx + (k + 2) * nx]
        return v
    for k in range(N):
        v[k * nx:(k + 1) * nx] = v[(k + 1) * nx:(k + 2) * nx]
    o = (N + 1) * nx
    for k in range(N - 1):
        v[o + k * nu: o + (k + 1) * nu] = v[o + (k + 1) * nu: o + (k + 2) * nu]
    return v


def solvers(nlp, kind):
    quiet = {"print_time": False}
    if kind == "ipopt":
        base = {"print_level": 0, "sb": "yes", "tol": 1e-8}
        warm = dict(base, warm_start_init_point="yes", warm_start_bound_push=1e-3,
                    warm_start_bound_frac=1e-3, warm_start_slack_bound_push=1e-3,
                    warm_start_slack_bound_frac=1e-3, warm_start_mult_bound_push=1e-3,
                    mu_init=1e-6)
        return (ca.nlpsol("cold", "ipopt", nlp, dict(quiet, ipopt=base)),
                ca.nlpsol("warm", "ipopt", nlp, dict(quiet, ipopt=warm)))
    sqp = dict(quiet, qpsol="qrqp", qpsol_options={"print_iter": False, "print_header": False,
                                                    "print_info": False, "error_on_fail": False},
               print_header=False, print_iteration=False, print_status=False,
               error_on_fail=False, tol_pr=1e-8, tol_du=1e-8)
    cold = ca.nlpsol("cold", "sqpmethod", nlp, dict(sqp, max_iter=3000))
    if kind == "sqp":
        return cold, ca.nlpsol("warm", "sqpmethod", nlp, dict(sqp, max_iter=3000))
    # RTI: the first step converged (as acados' initialisation), then one iteration each.
    return cold, ca.nlpsol("warm", "sqpmethod", nlp, dict(sqp, max_iter=1))


def run(name, kind):
    P = PROBLEMS[name]()
    nlp, lbw, ubw, w0, plant, cost = build(P)
    cold, warm = solvers(nlp, kind)
    nx = P["nx"]
    x = np.array(P["x_init"], dtype=float)
    prev = None
    states, controls, stats = [x.copy()], [], []
    J = 0.0
    for s in range(P["steps"]):
        t0 = time.perf_counter()
        if prev is None:
            out = cold(x0=w0, p=x, lbx=lbw, ubx=ubw, lbg=0, ubg=0)
            st = cold.stats()
        else:
            out = warm(x0=shift(np.array(prev["x"]).ravel(), P), p=x, lbx=lbw, ubx=ubw, lbg=0, ubg=0,
                       lam_x0=shift(np.array(prev["lam_x"]).ravel(), P),
                       lam_g0=shift(np.array(prev["lam_g"]).ravel(), P, rows=True))
            st = warm.stats()
        t = time.perf_counter() - t0
        prev = out
        wopt = np.array(out["x"]).ravel()
        u = wopt[(P["N"] + 1) * nx:(P["N"] + 1) * nx + P["nu"]]
        J += P["dt"] * float(cost(x, u))
        controls.append(u.copy())
        stats.append({"status": st["return_status"], "success": bool(st["success"]),
                      "iterations": st["iter_count"], "seconds": t})
        x = np.array(plant(x, u)).ravel()
        states.append(x.copy())
    lat = sorted(s["seconds"] for s in stats)
    # The warm steps: all but the cold first one (the loop's initialisation).
    warm_lat = sorted(s["seconds"] for s in stats[1:])
    its = [s["iterations"] for s in stats]
    return {"problem": name, "solver": kind, "closed_loop_cost": J,
            "all_succeeded": all(s["success"] for s in stats),
            "failed_steps": [i for i, s in enumerate(stats) if not s["success"]],
            "median_ms": 1e3 * float(np.median(lat)), "max_ms": 1e3 * lat[-1],
            "warm_median_ms": 1e3 * float(np.median(warm_lat)), "warm_max_ms": 1e3 * warm_lat[-1],
            "iterations_mean": float(np.mean(its)), "iterations_max": int(max(its)),
            "final_state": [float(v) for v in x]}


if __name__ == "__main__":
    names = sys.argv[1].split(",") if len(sys.argv) > 1 else list(PROBLEMS)
    kinds = sys.argv[2].split(",") if len(sys.argv) > 2 else ["ipopt", "sqp", "rti"]
    for n in names:
        for k in kinds:
            print(json.dumps(run(n, k)), flush=True)
