"""Reference optimum for nlp::ocp::MultiPhaseOcp: the brachistochrone to (2, 2) split
into two phases at x = 1, each with a free duration, joined by state continuity, written
again in CasADi Opti and solved by IPOPT (tol 1e-10). Held by nlp/tests/ocp_multi_phase.rs;
run `python3 benches/reference/ocp_multi_phase_casadi.py` (about 1 s) and copy the printed
values there.

Each phase: Hermite-Simpson (compressed), controls at the nodes (u_m = (u_k + u_{k+1})/2),
uniform grid of N intervals, h = T_i / N:
  x_m = (x_k + x_{k+1})/2 + h/8 (f_k - f_{k+1}),  x_{k+1} = x_k + h/6 (f_k + 4 f_m + f_{k+1}).
Problem: min T_a + T_b, x' = v sin(th), y' = v cos(th) (y downwards), v' = g cos(th),
g = 9.81, (x, y, v)(0) = 0 in phase a, x_a(T_a) = 1, x_b(0) = x_a(T_a) (all three states),
x_b(T_b) = 2, y_b(T_b) = 2, 0 <= th <= pi, 0.05 <= T_a, T_b <= 10.
The joint optimum is the one-phase brachistochrone's (the cycloid, T printed below), to the
discretisation error.
"""
import json
import math

import casadi as ca
import numpy as np

G = 9.81


def f(x, u):
    return ca.vertcat(x[2] * ca.sin(u[0]), x[2] * ca.cos(u[0]), G * ca.cos(u[0]))


def phase(opti, N, guess_from, guess_to):
    """Hermite-Simpson phase: returns (X, U, T)."""
    X = opti.variable(3, N + 1)
    U = opti.variable(1, N + 1)
    T = opti.variable()
    h = T / N
    for k in range(N):
        xa, xb, ua, ub = X[:, k], X[:, k + 1], U[:, k], U[:, k + 1]
        fa, fb = f(xa, ua), f(xb, ub)
        xm = (xa + xb) / 2 + h / 8 * (fa - fb)
        fm = f(xm, (ua + ub) / 2)
        opti.subject_to(xb == xa + h / 6 * (fa + 4 * fm + fb))
    opti.subject_to(opti.bounded(0, U, math.pi))
    opti.subject_to(opti.bounded(0.05, T, 10))
    s = np.linspace(0, 1, N + 1)
    for i in range(3):
        opti.set_initial(X[i, :], guess_from[i] + s * (guess_to[i] - guess_from[i]))
    opti.set_initial(U, math.pi / 4)
    opti.set_initial(T, 0.5)
    return X, U, T


def two_phase(Na, Nb):
    opti = ca.Opti()
    vmid, vend = math.sqrt(2 * G * 1.0), math.sqrt(2 * G * 2.0)
    Xa, Ua, Ta = phase(opti, Na, [0, 0, 0], [1, 1, vmid])
    Xb, Ub, Tb = phase(opti, Nb, [1, 1, vmid], [2, 2, vend])
    opti.subject_to(Xa[:, 0] == 0)
    opti.subject_to(Xa[0, Na] == 1)
    opti.subject_to(Xb[:, 0] == Xa[:, Na])
    opti.subject_to(Xb[0:2, Nb] == [2, 2])
    opti.minimize(Ta + Tb)
    opti.solver("ipopt", {"print_time": False}, {"tol": 1e-10, "print_level": 0, "sb": "yes"})
    sol = opti.solve()
    return {"problem": "brachistochrone_two_phase", "method": "hs", "Na": Na, "Nb": Nb,
            "status": opti.stats()["return_status"], "T": float(sol.value(Ta + Tb)),
            "Ta": float(sol.value(Ta)), "Tb": float(sol.value(Tb)),
            "y_switch": float(sol.value(Xa[1, Na]))}


def cycloid(g=G, x=2.0, y=2.0):
    """Closed form: x = r (phi - sin phi), y = r (1 - cos phi), T = phi_f sqrt(r / g)."""
    phi = 2.0
    for _ in range(50):
        F = (phi - math.sin(phi)) * y - (1 - math.cos(phi)) * x
        dF = (1 - math.cos(phi)) * y - math.sin(phi) * x
        phi -= F / dF
    r = y / (1 - math.cos(phi))
    # The time at which the cycloid passes x = 1: solve r (p - sin p) = 1.
    p = 1.0
    for _ in range(50):
        p -= (r * (p - math.sin(p)) - 1.0) / (r * (1 - math.cos(p)))
    return {"problem": "brachistochrone", "closed_form_T": phi * math.sqrt(r / g),
            "closed_form_Ta": p * math.sqrt(r / g), "closed_form_y_switch": r * (1 - math.cos(p))}


if __name__ == "__main__":
    for row in [two_phase(10, 10), cycloid()]:
        print(json.dumps(row))
