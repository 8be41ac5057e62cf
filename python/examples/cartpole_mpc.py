"""A cart-pole MPC loop: a multiple-shooting swing-up/stabilisation problem built once,
the measured state as a parameter, each step warm-started from the previous solution.

    python python/examples/cartpole_mpc.py
"""
import numpy as np

import symnlp as s

# %% Model: cart position p, pole angle th (0 = up), their rates; force u on the cart.
M, m, l, g = 1.0, 0.1, 0.5, 9.81


def f(x, u):
    p, th, v, w = x[0], x[1], x[2], x[3]
    den = M + m * s.sin(th) ** 2
    a = (u + m * s.sin(th) * (l * w**2 - g * s.cos(th))) / den
    alpha = (-u * s.cos(th) - m * l * w**2 * s.sin(th) * s.cos(th) + (M + m) * g * s.sin(th)) / (l * den)
    return s.vertcat(v, w, a, alpha)


def rk4(x, u, dt):
    k1 = f(x, u)
    k2 = f(x + dt / 2 * k1, u)
    k3 = f(x + dt / 2 * k2, u)
    k4 = f(x + dt * k3, u)
    return x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


# %% The MPC problem: horizon N, states X[:, k], controls U[k], measured state x0.
N, dt = 20, 0.05
pb = s.Problem()
X = [pb.variable(f"X{k}", 4) for k in range(N + 1)]
U = pb.variable("u", N)
x0 = pb.parameter("x_measured", 4)
pb.subject_to(X[0] == x0, name="initial state")
cost = 0
for k in range(N):
    pb.subject_to(X[k + 1] == rk4(X[k], U[k], dt), name=f"dynamics {k}")
    cost = cost + s.sumsqr(X[k]) + 0.01 * U[k] ** 2
pb.minimize(cost + 10 * s.sumsqr(X[N]))
pb.subject_to(pb.bounded(-20, U, 20), name="force")

# %% Closed loop: measure, solve (warm), apply the first control to the "plant".
plant = s.Function("plant", [s.vertcat(*X[0]), U[0]], [rk4(X[0], U[0], dt)])
x = np.array([0.0, 0.3, 0.0, 0.0])  # pole 0.3 rad from upright
previous, log = None, []
for step in range(40):
    pb.set_value(x0, x)
    sol = pb.solve(options={"print_level": 0}) if previous is None else pb.solve_warm(previous)
    assert sol.success, sol.status
    u0 = float(sol.value(U[0]))
    x = plant(x, u0)
    log.append((step, x[1], u0, sol.stats["iter_count"]))
    previous = sol

for step, th, u0, it in log[::8]:
    print(f"step {step:2d}: angle {th:+.4f} rad, force {u0:+.3f} N, {it} iterations")
print(f"final angle {x[1]:+.2e} rad")
