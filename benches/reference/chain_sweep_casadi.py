"""CasADi half of the hanging-chain line-count pair (issue 22 item 6; the symnlp half is
examples/examples/chain_sweep.rs): n links between x = 0 and x = 1, the chain's length and end
heights as parameters, re-solved 20 times, each solve warm-started from the last.
Run: python3 benches/reference/chain_sweep_casadi.py (casadi 3.8.2, benches/reference/setup.sh)."""
import casadi as ca
import numpy as np

n = 20
opti = ca.Opti()
x = opti.variable(n + 1)
y = opti.variable(n + 1)
p = opti.parameter(3)  # length, left and right end heights
opti.minimize(ca.sum1(y))  # potential energy of equal masses
opti.subject_to([x[0] == 0, x[n] == 1, y[0] == p[1], y[n] == p[2]])
for i in range(n):
    opti.subject_to((x[i + 1] - x[i]) ** 2 + (y[i + 1] - y[i]) ** 2 == (p[0] / n) ** 2)
opti.set_initial(x, np.linspace(0, 1, n + 1))
opti.set_initial(y, np.linspace(1, 0.5, n + 1))
opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "sb": "yes"})

for k in range(20):
    L, b = 1.5 + 0.05 * k, 0.5 + 0.02 * k
    opti.set_value(p, [L, 1.0, b])
    sol = opti.solve()
    print(f"L = {L:.2f}, b = {b:.2f}: energy {sol.value(opti.f):.8f}")
    opti.set_initial(sol.value_variables())  # warm start the next solve
