"""CasADi's version of python/examples/hanging_chain.py (casadi.Opti, same formulation):
a sweep of the right end's height, each solve warm-started from the previous one."""
import casadi as ca
import numpy as np

# %% Build once: n masses, links at most L/(n-1) long, the end points are parameters.
n, L = 40, 1.4
opti = ca.Opti()
px = opti.variable(n)
py = opti.variable(n)
ends = opti.parameter(4)  # (x0, y0, x1, y1)
opti.minimize(ca.sum1(py))  # potential energy of equal masses
seg = L / (n - 1)
for i in range(n - 1):
    opti.subject_to((px[i + 1] - px[i]) ** 2 + (py[i + 1] - py[i]) ** 2 <= seg**2)
opti.subject_to(ca.vertcat(px[0], py[0], px[n - 1], py[n - 1]) == ends)
opti.set_initial(px, np.linspace(0, 1, n))
opti.set_initial(py, np.linspace(1, 0.5, n))
opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "sb": "yes"})

# %% Sweep the right end's height; warm start each solve from the last.
heights = np.linspace(0.2, 1.0, 5)
chains = []
for h in heights:
    opti.set_value(ends, [0.0, 1.0, 1.0, h])
    sol = opti.solve()
    chains.append((sol.value(px), sol.value(py), sol.value(opti.f), sol.stats()["iter_count"]))
    opti.set_initial(sol.value_variables())
    opti.set_initial(opti.lam_g, sol.value(opti.lam_g))

for h, (_, _, f, it) in zip(heights, chains):
    print(f"right end at y = {h:.2f}: energy {f:.6f} in {it} iterations")
