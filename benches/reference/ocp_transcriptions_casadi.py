"""Reference optima for the trapezoidal and Hermite-Simpson transcriptions of nlp::ocp
(Method::trapezoidal, Method::hermite_simpson[_separated], controls at the nodes,
uniform or user-given grids), written again in CasADi Opti and solved by IPOPT
(tol 1e-10). Held by nlp/tests/ocp_transcriptions.rs; run
`python3 benches/reference/ocp_transcriptions_casadi.py` (about 2 s) and copy the printed
optima there.

The transcriptions, with controls u_k at the nodes t_k = s_k T (k = 0..N), h_k = t_{k+1} - t_k:
  trapezoidal:     x_{k+1} = x_k + h_k/2 (f_k + f_{k+1}),    cost h_k/2 (l_k + l_{k+1})
  Hermite-Simpson: x_m = (x_k + x_{k+1})/2 + h_k/8 (f_k - f_{k+1}), u_m = (u_k + u_{k+1})/2,
                   x_{k+1} = x_k + h_k/6 (f_k + 4 f_m + f_{k+1}),
                   cost h_k/6 (l_k + 4 l_m + l_{k+1});
                   separated: x_m a variable with x_m = the expression above.

Problems:
  goddard:  COPS 3.0 (Dolan, More, Munson, ANL/MCS-TM-246, 2004, problem 10) as its AMPL
            model writes it: trapezoidal, thrust at the nodes, free final time, N = 100,
            the COPS initial guess. COPS reports h(T) = 1.01283.
  bryson_denham: min 1/2 int_0^1 u^2, x' = v, v' = u, x(0) = x(1) = 0, v(0) = -v(1) = 1,
            x <= 1/9. Closed form (Bryson & Ho 1975, sec. 3.11): J = 4/(9 l) = 4.
  brachistochrone: min T, x' = v sin(th), y' = v cos(th) (y downwards), v' = g cos(th),
            g = 9.81, (x, y, v)(0) = 0, x(T) = 2, y(T) = 2, 0 <= th <= pi. Closed form: the
            cycloid, T printed below.
"""
import json
import math

import casadi as ca
import numpy as np


def transcribe(opti, f, l, nx, nu, N, T, method, fractions=None):
    """States X (nx x N+1) and node controls U (nu x N+1); returns (X, U, cost)."""
    X = opti.variable(nx, N + 1)
    U = opti.variable(nu, N + 1)
    s = np.linspace(0, 1, N + 1) if fractions is None else np.asarray(fractions)
    Xm = opti.variable(nx, N) if method == "hs_separated" else None
    cost = 0
    for k in range(N):
        h = T * (s[k + 1] - s[k]) if fractions is not None else T / N
        xa, xb, ua, ub = X[:, k], X[:, k + 1], U[:, k], U[:, k + 1]
        fa, fb = f(xa, ua), f(xb, ub)
        la, lb = l(xa, ua), l(xb, ub)
        if method == "trapezoidal":
            opti.subject_to(xb == xa + h / 2 * (fa + fb))
            cost += h / 2 * (la + lb)
        else:
            cubic = (xa + xb) / 2 + h / 8 * (fa - fb)
            if Xm is not None:
                opti.subject_to(Xm[:, k] == cubic)
                xm = Xm[:, k]
            else:
                xm = cubic
            um = (ua + ub) / 2
            fm, lm = f(xm, um), l(xm, um)
            opti.subject_to(xb == xa + h / 6 * (fa + 4 * fm + fb))
            cost += h / 6 * (la + 4 * lm + lb)
    return X, U, Xm, cost


def solve(opti):
    opti.solver("ipopt", {"print_time": False}, {"tol": 1e-10, "print_level": 0, "sb": "yes"})
    sol = opti.solve()
    return sol, opti.stats()["return_status"]


def goddard(N=100):
    h0, v0, m0, g0, Tc, hc, vc, mc = 1.0, 0.0, 1.0, 1.0, 3.5, 500.0, 620.0, 0.6
    c = 0.5 * math.sqrt(g0 * h0)
    mf, Dc, Tmax = mc * m0, 0.5 * vc * m0 / g0, Tc * g0 * m0

    def f(x, u):
        h, v, m = x[0], x[1], x[2]
        D = Dc * v**2 * ca.exp(-hc * (h - h0) / h0)
        g = g0 * (h0 / h) ** 2
        return ca.vertcat(v, (u[0] - D) / m - g, -u[0] / c)

    opti = ca.Opti()
    tf = opti.variable()
    X, U, _, _ = transcribe(opti, f, lambda x, u: 0, 3, 1, N, tf, "trapezoidal")
    opti.minimize(-X[0, N])
    opti.subject_to(X[:, 0] == [h0, v0, m0])
    opti.subject_to(X[2, N] == mf)
    opti.subject_to(opti.bounded(h0, X[0, :], ca.inf))
    opti.subject_to(opti.bounded(0, X[1, :], ca.inf))
    opti.subject_to(opti.bounded(mf, X[2, :], m0))
    opti.subject_to(opti.bounded(0, U, Tmax))
    opti.subject_to(tf >= 0)
    t = np.linspace(0, 1, N + 1)
    opti.set_initial(X[0, :], 1.0)
    opti.set_initial(X[1, :], t * (1 - t))
    opti.set_initial(X[2, :], (mf - m0) * t + m0)
    opti.set_initial(U, Tmax / 2)
    opti.set_initial(tf, 1.0)
    sol, status = solve(opti)
    return {"problem": "goddard", "method": "trapezoidal", "N": N, "status": status,
            "h_final": float(sol.value(X[0, N])), "T": float(sol.value(tf))}


def bryson_denham(method, N, fractions=None):
    opti = ca.Opti()
    f = lambda x, u: ca.vertcat(x[1], u[0])
    X, U, Xm, cost = transcribe(opti, f, lambda x, u: 0.5 * u[0] ** 2, 2, 1, N, 1.0, method,
                                fractions)
    opti.minimize(cost)
    opti.subject_to(X[:, 0] == [0, 1])
    opti.subject_to(X[:, N] == [0, -1])
    opti.subject_to(X[0, :] <= 1.0 / 9.0)
    if Xm is not None:
        opti.subject_to(Xm[0, :] <= 1.0 / 9.0)
    sol, status = solve(opti)
    out = {"problem": "bryson_denham", "method": method, "N": N, "status": status,
           "objective": float(sol.value(cost))}
    if fractions is not None:
        out["fractions"] = "10 uniform intervals on [0, 0.25], 20 on [0.25, 1]"
    return out


def brachistochrone(method, N):
    g = 9.81
    f = lambda x, u: ca.vertcat(x[2] * ca.sin(u[0]), x[2] * ca.cos(u[0]), g * ca.cos(u[0]))
    opti = ca.Opti()
    tf = opti.variable()
    X, U, Xm, _ = transcribe(opti, f, lambda x, u: 0, 3, 1, N, tf, method)
    opti.minimize(tf)
    opti.subject_to(X[:, 0] == [0, 0, 0])
    opti.subject_to(X[0:2, N] == [2, 2])
    opti.subject_to(opti.bounded(0, U, math.pi))
    opti.subject_to(opti.bounded(0.1, tf, 10))
    t = np.linspace(0, 1, N + 1)
    opti.set_initial(X[0, :], 2 * t)
    opti.set_initial(X[1, :], 2 * t)
    opti.set_initial(X[2, :], math.sqrt(2 * g * 2) * t)
    if Xm is not None:
        tm = (t[:-1] + t[1:]) / 2
        opti.set_initial(Xm[0, :], 2 * tm)
        opti.set_initial(Xm[1, :], 2 * tm)
        opti.set_initial(Xm[2, :], math.sqrt(2 * g * 2) * tm)
    opti.set_initial(U, math.pi / 4)
    opti.set_initial(tf, 1.0)
    sol, status = solve(opti)
    return {"problem": "brachistochrone", "method": method, "N": N, "status": status,
            "T": float(sol.value(tf))}


def cycloid_time(g=9.81, x=2.0, y=2.0):
    """Closed form: x = r (phi - sin phi), y = r (1 - cos phi), T = phi_f sqrt(r / g)."""
    phi = 2.0
    for _ in range(50):  # Newton on (phi - sin phi) y - (1 - cos phi) x = 0
        F = (phi - math.sin(phi)) * y - (1 - math.cos(phi)) * x
        dF = (1 - math.cos(phi)) * y - math.sin(phi) * x
        phi -= F / dF
    r = y / (1 - math.cos(phi))
    return phi * math.sqrt(r / g)


if __name__ == "__main__":
    fr = list(np.linspace(0, 0.25, 11)[:-1]) + list(np.linspace(0.25, 1, 21))
    rows = [
        goddard(100),
        bryson_denham("trapezoidal", 30),
        bryson_denham("hs", 30),
        bryson_denham("hs_separated", 30),
        bryson_denham("hs", 30, fr),
        brachistochrone("trapezoidal", 40),
        brachistochrone("hs", 20),
        brachistochrone("hs_separated", 20),
        {"problem": "brachistochrone", "closed_form_T": cycloid_time()},
    ]
    for r in rows:
        print(json.dumps(r))
