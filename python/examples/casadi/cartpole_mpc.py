"""CasADi's version of python/examples/cartpole_mpc.py (casadi.Opti, same formulation):
a multiple-shooting MPC loop, the measured state as a parameter, warm starts."""
import casadi as ca
import numpy as np

# %% Model: cart position p, pole angle th (0 = up), their rates; force u on the cart.
M, m, l, g = 1.0, 0.1, 0.5, 9.81


def f(x, u):
    p, th, v, w = x[0], x[1], x[2], x[3]
    den = M + m * ca.sin(th) ** 2
    a = (u + m * ca.sin(th) * (l * w**2 - g * ca.cos(th))) / den
    alpha = (-u * ca.cos(th) - m * l * w**2 * ca.sin(th) * ca.cos(th) + (M + m) * g * ca.sin(th)) / (l * den)
    return ca.vertcat(v, w, a, alpha)


def rk4(x, u, dt):
    k1 = f(x, u)
    k2 = f(x + dt / 2 * k1, u)
    k3 = f(x + dt / 2 * k2, u)
    k4 = f(x + dt * k3, u)
    return x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


# %% The MPC problem: horizon N, states X[:, k], controls U[k], measured state x0.
N, dt = 20, 0.05
opti = ca.Opti()
X = [opti.variable(4) for k in range(N + 1)]
U = opti.variable(N)
x0 = opti.parameter(4)
opti.subject_to(X[0] == x0)
cost = 0
for k in range(N):
    opti.subject_to(X[k + 1] == rk4(X[k], U[k], dt))
    cost = cost + ca.sumsqr(X[k]) + 0.01 * U[k] ** 2
opti.minimize(cost + 10 * ca.sumsqr(X[N]))
opti.subject_to(opti.bounded(-20, U, 20))
opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "sb": "yes"})

# %% Closed loop: measure, solve (warm), apply the first control to the "plant".
xs, us = ca.SX.sym("x", 4), ca.SX.sym("u")
plant = ca.Function("plant", [xs, us], [rk4(xs, us, dt)])
x = np.array([0.0, 0.3, 0.0, 0.0])  # pole 0.3 rad from upright
log = []
for step in range(40):
    opti.set_value(x0, x)
    sol = opti.solve()
    u0 = float(sol.value(U[0]))
    x = np.array(plant(x, u0)).ravel()
    log.append((step, x[1], u0, sol.stats()["iter_count"]))
    opti.set_initial(sol.value_variables())
    opti.set_initial(opti.lam_g, sol.value(opti.lam_g))

for step, th, u0, it in log[::8]:
    print(f"step {step:2d}: angle {th:+.4f} rad, force {u0:+.3f} N, {it} iterations")
print(f"final angle {x[1]:+.2e} rad")
