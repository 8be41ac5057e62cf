"""The Goddard rocket (COPS 3.0 problem 10) with symnlp.Ocp: maximise the final altitude,
trapezoidal rule with the thrust at the nodes, free final time, N = 100; plots the
trajectory. Notebook-style: run it cell by cell in Jupyter (`# %%`), or as a script, which
writes goddard_rocket.png. CasADi's version: casadi/goddard_rocket.py.

    python python/examples/goddard_rocket.py
"""
import math

import symnlp as s

# %% Model: altitude h, velocity v, mass m; thrust T at the nodes. COPS's constants.
h0, m0, g0, hc, vc = 1.0, 1.0, 1.0, 500.0, 620.0
c, mf, dc, tmax = 0.5 * math.sqrt(g0 * h0), 0.6 * m0, 0.5 * vc * m0 / g0, 3.5 * g0 * m0


def f(x, u, p):
    drag = dc * x[1] ** 2 * s.exp(-hc * (x[0] - h0) / h0)
    return [x[1], (u[0] - drag) / x[2] - g0 * (h0 / x[0]) ** 2, -u[0] / c]


ocp = s.Ocp(["h", "v", "m"], ["T"])
ocp.set_dynamics(f)
ocp.set_terminal_cost(lambda xT, p, T: -xT[0])  # maximise h(T)
ocp.set_free_horizon(0.0, math.inf, 1.0)
ocp.set_initial_state([h0, 0.0, m0])
ocp.add_boundary_constraint("final mass", lambda x0, xT, p, T: xT[2] == mf)
ocp.set_state_bounds([h0, 0.0, mf], [None, None, m0])
ocp.set_control_bounds([0.0], [tmax])
ocp.set_control_interpolation("linear")
ocp.set_state_guess(lambda t: [1.0, t * (1 - t), (mf - m0) * t + m0])
ocp.set_control_guess(lambda t: [tmax / 2])

# %% Transcribe and solve.
tr = ocp.transcribe(s.Method.trapezoidal(), 100)
sol = tr.solve(options={"tol": 1e-10})
traj = tr.trajectory(sol)
print(f"{traj.status}: h(T) = {traj.state('h')[-1]:.7f}, T = {traj.final_time:.7f}")

# %% Plot (skipped when matplotlib is not installed).
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    plt = None
if plt is not None:
    fig, axes = plt.subplots(4, 1, sharex=True, figsize=(6, 7))
    for ax, name in zip(axes, traj.state_names):
        ax.plot(traj.time, traj.state(name))
        ax.set_ylabel(name)
    axes[3].plot(traj.control_time, traj.control("T"))  # linear between nodes
    axes[3].set_ylabel("thrust")
    axes[3].set_xlabel("t")
    fig.suptitle("Goddard rocket (COPS 3.0), trapezoidal, N = 100")
    fig.savefig("goddard_rocket.png", dpi=110)
