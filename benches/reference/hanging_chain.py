"""Hanging chain benchmark problem (CasADi SX reference formulation).

The Rust side (symnlp) implements exactly the same problem; keep both in sync.

Chain with N links and N+1 points p_i = (x_i, y_i), i = 0..N.

Variables (n = 2(N+1)), ordered
    w = [x_0, y_0, x_1, y_1, ..., x_N, y_N]
    i.e. x_i = w[2i], y_i = w[2i+1].

Bounds (fixed end points via lb = ub; everything else free, +-inf):
    x_0 = 0, y_0 = 0, x_N = 1, y_N = 0.

Constraints (m = N equalities, lbg = ubg = 0), in order i = 0..N-1:
    g_i = (x_{i+1} - x_i)^2 + (y_{i+1} - y_i)^2 - (L/N)^2 = 0,   L = 2.

Objective (potential energy, uniform mass):
    f = (1/N) * sum_{i=0}^{N} y_i.

Initial guess:
    x_i = i/N,  y_i = -0.5 * sin(pi * i / N).
"""
import math

import casadi as ca
import numpy as np

LENGTH = 2.0


def n_vars(N):
    return 2 * (N + 1)


def build(N):
    """Return dict(x, f, g, lbx, ubx, lbg, ubg, x0) with x/f/g CasADi SX."""
    n = n_vars(N)
    w = ca.SX.sym("w", n)
    ws = ca.vertsplit(w)  # scalar SX elements (much cheaper than w[k] indexing)
    xs = ws[0::2]
    ys = ws[1::2]
    seg2 = (LENGTH / N) ** 2
    g = [(xs[i + 1] - xs[i]) ** 2 + (ys[i + 1] - ys[i]) ** 2 - seg2 for i in range(N)]
    f = ys[0]
    for i in range(1, N + 1):
        f = f + ys[i]
    f = f / N

    lbx = np.full(n, -np.inf)
    ubx = np.full(n, np.inf)
    lbx[0] = ubx[0] = 0.0  # x_0
    lbx[1] = ubx[1] = 0.0  # y_0
    lbx[2 * N] = ubx[2 * N] = 1.0  # x_N
    lbx[2 * N + 1] = ubx[2 * N + 1] = 0.0  # y_N

    x0 = np.empty(n)
    for i in range(N + 1):
        x0[2 * i] = i / N
        x0[2 * i + 1] = -0.5 * math.sin(math.pi * i / N)

    return dict(
        x=w,
        f=f,
        g=ca.vertcat(*g),
        lbx=lbx,
        ubx=ubx,
        lbg=np.zeros(N),
        ubg=np.zeros(N),
        x0=x0,
    )


if __name__ == "__main__":
    p = build(10)
    print(p["x"].shape, p["g"].shape, p["f"])
