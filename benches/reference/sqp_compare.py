"""Cart-pole swing-up MPC of testkit/src/cart_pole_mpc.rs, identical transcription, in CasADi
3.8.2: N = 40, dt = 0.05, one RK4 step per interval, variables [X_0, U_0, ..., X_N],
constraints [X_0 - x0, X_{k+1} - F(X_k, U_k)], |u| <= 20, |cart position| <= 2, cost
sum_k dt (Q (x - goal)^2 + R u^2) + 10 Q (x_N - goal)^2. 100 closed-loop steps from the
hanging state, warm started from the previous solution shifted one stage (x, lam_g,
lam_x; cold at step 0), with IPOPT and with sqpmethod + qrqp.

Prints one line per solver: median and max latency (wall time of the solver call),
iterations mean/max, closed-loop cost, failed steps. The symnlp side of the same table:
cargo test --release -p nlp --test sqp_mpc -- --ignored --nocapture cart_pole_loop_report
"""
import math
import sys
import time

import casadi as ca
import numpy as np

NX, NU, N, DT = 4, 1, 40, 0.05
GOAL = [0.0, math.pi, 0.0, 0.0]
Q = [10.0, 10.0, 0.1, 0.1]
R = 0.01
STAGE = NX + NU


def dynamics(x, u):
    l, m1, m2, g = 0.5, 1.0, 0.3, 9.81
    s, c = ca.sin(x[1]), ca.cos(x[1])
    ddq1 = (l * m2 * s * x[3] ** 2 + u + m2 * g * c * s) / (m1 + m2 * (1.0 - c**2))
    ddq2 = -(l * m2 * c * s * x[3] ** 2 + u * c + (m1 + m2) * g * s) / (
        l * m1 + l * m2 * (1.0 - c**2)
    )
    return ca.vertcat(x[2], x[3], ddq1, ddq2)


def rk4(x, u, h):
    k1 = dynamics(x, u)
    k2 = dynamics(x + h / 2 * k1, u)
    k3 = dynamics(x + h / 2 * k2, u)
    k4 = dynamics(x + h * k3, u)
    return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def build():
    w = ca.SX.sym("w", N * STAGE + NX)
    p = ca.SX.sym("x0", NX)
    X = lambda k: w[k * STAGE : k * STAGE + NX]
    U = lambda k: w[k * STAGE + NX]
    f = 0
    for k in range(N):
        for i in range(NX):
            f += Q[i] * DT * (X(k)[i] - GOAL[i]) ** 2
        f += R * DT * U(k) ** 2
    for i in range(NX):
        f += Q[i] * 10.0 * (X(N)[i] - GOAL[i]) ** 2
    g = [X(0) - p]
    for k in range(N):
        g.append(X(k + 1) - rk4(X(k), U(k), DT))
    lbw = -np.inf * np.ones(w.shape[0])
    ubw = np.inf * np.ones(w.shape[0])
    for k in range(N):
        lbw[k * STAGE + NX], ubw[k * STAGE + NX] = -20.0, 20.0
    for k in range(N + 1):
        lbw[k * STAGE], ubw[k * STAGE] = -2.0, 2.0
    return {"x": w, "p": p, "f": f, "g": ca.vertcat(*g)}, lbw, ubw


_xs, _us = ca.SX.sym("x", NX), ca.SX.sym("u")
PLANT = ca.Function("plant", [_xs, _us], [rk4(_xs, _us, DT)])


def stage_cost(x, u):
    return sum(Q[i] * (x[i] - GOAL[i]) ** 2 for i in range(NX)) * DT + R * u * u * DT


def shift(v, stride):
    v = np.array(v).flatten()
    out = v.copy()
    out[: len(v) - stride] = v[stride:]
    return out


def closed_loop(solver, steps=100):
    _, lbw, ubw = build()
    ng = NX * (N + 1)
    x = np.zeros(NX)
    w0, lam_g, lam_x = np.zeros(N * STAGE + NX), None, None
    secs, iters, fails, cost = [], [], [], 0.0
    for k in range(steps):
        args = dict(x0=w0, p=x, lbx=lbw, ubx=ubw, lbg=np.zeros(ng), ubg=np.zeros(ng))
        if lam_g is not None:
            args.update(lam_g0=lam_g, lam_x0=lam_x)
        t = time.perf_counter()
        sol = solver(**args)
        secs.append(time.perf_counter() - t)
        st = solver.stats()
        iters.append(st["iter_count"])
        if not st["success"]:
            fails.append(f"{k}:{st['return_status']}")
        wopt = np.array(sol["x"]).flatten()
        u = wopt[NX]
        cost += stage_cost(x, u)
        x = np.array(PLANT(x, u)).flatten()
        w0 = shift(wopt, STAGE)
        lam_g = shift(sol["lam_g"], NX)
        lam_x = shift(sol["lam_x"], STAGE)
    return secs, iters, fails, cost


def report(name, res):
    secs, iters, fails, cost = res
    s = sorted(secs)
    print(
        f"{name}: median {s[len(s)//2]*1e3:.2f} ms, max {s[-1]*1e3:.1f} ms, "
        f"iterations mean {np.mean(iters):.2f} max {max(iters)}, "
        f"closed-loop cost {cost:.6f}, failures {fails}"
    )


def main():
    steps = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    nlp, _, _ = build()
    ipopt = ca.nlpsol(
        "ipopt", "ipopt", nlp,
        {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes",
         "ipopt.warm_start_init_point": "yes"},
    )
    qr = {"print_iter": False, "print_header": False, "print_info": False,
          "error_on_fail": False}
    sqp = ca.nlpsol(
        "sqp", "sqpmethod", nlp,
        {"qpsol": "qrqp", "qpsol_options": qr, "print_time": False,
         "print_header": False, "print_iteration": False, "print_status": False,
         "error_on_fail": False},
    )
    report("casadi ipopt", closed_loop(ipopt, steps))
    report("casadi sqpmethod+qrqp", closed_loop(sqp, steps))


if __name__ == "__main__":
    main()
