"""The Goddard rocket of COPS 3.0 (problem 10) in CasADi Opti, written as a CasADi user
would: trapezoidal rule with the thrust at the nodes, free final time, N = 100, COPS's
initial guess. The CasADi half of python/examples/goddard_rocket.py and of docs/casadi.md's
line-count comparison (examples/src/goddard_rocket.rs). Prints h(T) = 1.0128320 (COPS: 1.01283)."""
import casadi as ca
import numpy as np

h0, v0, m0, g0, Tc, hc, vc, mc = 1.0, 0.0, 1.0, 1.0, 3.5, 500.0, 620.0, 0.6
c = 0.5 * np.sqrt(g0 * h0)
mf, Dc, Tmax = mc * m0, 0.5 * vc * m0 / g0, Tc * g0 * m0
N = 100


def f(x, u):
    D = Dc * x[1] ** 2 * ca.exp(-hc * (x[0] - h0) / h0)
    g = g0 * (h0 / x[0]) ** 2
    return ca.vertcat(x[1], (u - D) / x[2] - g, -u / c)


opti = ca.Opti()
X = opti.variable(3, N + 1)
U = opti.variable(1, N + 1)
tf = opti.variable()
h = tf / N
for k in range(N):
    opti.subject_to(X[:, k + 1] == X[:, k] + h / 2 * (f(X[:, k], U[k]) + f(X[:, k + 1], U[k + 1])))
opti.minimize(-X[0, N])
opti.subject_to(X[:, 0] == [h0, v0, m0])
opti.subject_to(X[2, N] == mf)
opti.subject_to(opti.bounded(h0, X[0, :], ca.inf))
opti.subject_to(X[1, :] >= 0)
opti.subject_to(opti.bounded(mf, X[2, :], m0))
opti.subject_to(opti.bounded(0, U, Tmax))
opti.subject_to(tf >= 0)
t = np.linspace(0, 1, N + 1)
opti.set_initial(X[0, :], 1.0)
opti.set_initial(X[1, :], t * (1 - t))
opti.set_initial(X[2, :], (mf - m0) * t + m0)
opti.set_initial(U, Tmax / 2)
opti.set_initial(tf, 1.0)
opti.solver("ipopt", {"print_time": False}, {"tol": 1e-10, "print_level": 0, "sb": "yes"})
sol = opti.solve()
print(f"{opti.stats()['return_status']}: h(T) = {sol.value(X[0, N]):.7f}, T = {sol.value(tf):.7f}")
