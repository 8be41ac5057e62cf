"""CasADi's Opti race-car example (casadi/docs/examples/python/race_car.py), unchanged
formulation: minimum time to drive 1 m with a position-dependent speed limit, RK4 over N
control intervals. Prints the optimal final time and IPOPT's iteration count as JSON; the
Rust counterpart is examples/src/race_car.rs (tested in tests/race_car.rs).

Usage: python3 benches/reference/race_car.py [N]
"""
import json
import sys

from casadi import Opti, pi, sin, vertcat

N = int(sys.argv[1]) if len(sys.argv) > 1 else 100
opti = Opti()
X = opti.variable(2, N + 1)
pos, speed = X[0, :], X[1, :]
U = opti.variable(1, N)
T = opti.variable()
opti.minimize(T)


def f(x, u):
    return vertcat(x[1], u - x[1])


dt = T / N
for k in range(N):
    k1 = f(X[:, k], U[:, k])
    k2 = f(X[:, k] + dt / 2 * k1, U[:, k])
    k3 = f(X[:, k] + dt / 2 * k2, U[:, k])
    k4 = f(X[:, k] + dt * k3, U[:, k])
    opti.subject_to(X[:, k + 1] == X[:, k] + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4))
opti.subject_to(speed <= 1 - sin(2 * pi * pos) / 2)
opti.subject_to(opti.bounded(0, U, 1))
opti.subject_to(pos[0] == 0)
opti.subject_to(speed[0] == 0)
opti.subject_to(pos[-1] == 1)
opti.subject_to(T >= 0)
opti.set_initial(speed, 1)
opti.set_initial(T, 1)
opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "sb": "yes", "tol": 1e-8})
sol = opti.solve()
stats = opti.stats()
print(json.dumps({"N": N, "T": float(sol.value(T)), "iterations": stats["iter_count"],
                  "status": stats["return_status"]}))
