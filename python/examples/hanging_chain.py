"""Parametric hanging chain: a sweep of the right end's height, each solve warm-started
from the previous one without rebuilding the problem; plots the chains (notebook-style:
run it cell by cell in Jupyter, or as a script, which writes hanging_chain.png).

    python python/examples/hanging_chain.py
"""
import numpy as np

import symnlp as s

# %% Build once: n masses, links at most L/(n-1) long, the end points are parameters.
n, L = 40, 1.4
pb = s.Problem()
px = pb.variable("px", n)
py = pb.variable("py", n)
ends = pb.parameter("ends", 4)  # (x0, y0, x1, y1)
pb.minimize(s.sum1(py))  # potential energy of equal masses
seg = L / (n - 1)
for i in range(n - 1):
    pb.subject_to((px[i + 1] - px[i]) ** 2 + (py[i + 1] - py[i]) ** 2 <= seg**2, name=f"link {i}")
pb.subject_to(s.vertcat(px[0], py[0], px[n - 1], py[n - 1]) == ends, name="ends")
pb.set_initial(px, np.linspace(0, 1, n))
pb.set_initial(py, np.linspace(1, 0.5, n))

# %% Sweep the right end's height; warm start each solve from the last.
heights = np.linspace(0.2, 1.0, 5)  # reachable: |(1, h - 1)| < 1.4
chains, previous = [], None
for h in heights:
    pb.set_value(ends, [0.0, 1.0, 1.0, h])
    sol = pb.solve() if previous is None else pb.solve_warm(previous)
    assert sol.success, sol.status
    chains.append((sol.value(px), sol.value(py), sol.objective, sol.stats["iter_count"]))
    previous = sol

for h, (_, _, f, it) in zip(heights, chains):
    print(f"right end at y = {h:.2f}: energy {f:.6f} in {it} iterations")

# %% Plot (skipped when matplotlib is not installed).
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    plt = None
if plt is not None:
    fig, ax = plt.subplots(figsize=(6, 4))
    for h, (x, y, _, _) in zip(heights, chains):
        ax.plot(x, y, ".-", label=f"y1 = {h:.1f}")
    ax.set_aspect("equal")
    ax.legend(fontsize=7)
    ax.set_title("Hanging chain, 40 masses")
    fig.savefig("hanging_chain.png", dpi=120)
