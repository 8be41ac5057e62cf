"""Van der Pol optimal control problem, implicit-midpoint transcription
(CasADi SX reference formulation).

The Rust side (symnlp) implements exactly the same problem; keep both in sync.

N intervals, horizon T = 10, step h = T/N.
Dynamics f(x, u) = [ (1 - x2^2) * x1 - x2 + u,  x1 ].

Variables (n = 3N + 2), ordered per interval:
    w = [x1_0, x2_0, u_0, x1_1, x2_1, u_1, ..., x1_{N-1}, x2_{N-1}, u_{N-1}, x1_N, x2_N]
    i.e. x1_k = w[3k], x2_k = w[3k+1], u_k = w[3k+2] (k < N); x1_N = w[3N], x2_N = w[3N+1].

Bounds:
    x1_0 = 0, x2_0 = 1            (fixed via lb = ub)
    -1 <= u_k <= 1                (k = 0..N-1)
    x1_k >= -0.25                 (k = 1..N, i.e. including the final state x1_N)
    x2_k free for k >= 1.

Constraints (m = 2N equalities, lbg = ubg = 0), for k = 0..N-1, in order
first component then second (g[2k], g[2k+1]):
    x_{k+1} - x_k - h * f((x_k + x_{k+1}) / 2, u_k) = 0.

Objective:
    J = h * sum_{k=0}^{N-1} (x1_k^2 + x2_k^2 + u_k^2).

Initial guess: all zeros except the fixed initial state (x1_0 = 0, x2_0 = 1).
"""
import casadi as ca
import numpy as np

T = 10.0


def n_vars(N):
    return 3 * N + 2


def dynamics(x1, x2, u):
    return (1 - x2 ** 2) * x1 - x2 + u, x1


def build(N):
    """Return dict(x, f, g, lbx, ubx, lbg, ubg, x0) with x/f/g CasADi SX."""
    n = n_vars(N)
    h = T / N
    w = ca.SX.sym("w", n)
    ws = ca.vertsplit(w)  # scalar SX elements (much cheaper than w[k] indexing)
    X1 = ws[0::3]
    X2 = ws[1::3]
    U = ws[2::3]
    assert len(X1) == N + 1 and len(X2) == N + 1 and len(U) == N

    g = []
    J = 0
    for k in range(N):
        m1 = (X1[k] + X1[k + 1]) / 2
        m2 = (X2[k] + X2[k + 1]) / 2
        f1, f2 = dynamics(m1, m2, U[k])
        g.append(X1[k + 1] - X1[k] - h * f1)
        g.append(X2[k + 1] - X2[k] - h * f2)
        J = J + (X1[k] ** 2 + X2[k] ** 2 + U[k] ** 2)
    J = h * J

    lbx = np.full(n, -np.inf)
    ubx = np.full(n, np.inf)
    lbx[0] = ubx[0] = 0.0  # x1_0
    lbx[1] = ubx[1] = 1.0  # x2_0
    for k in range(N):
        lbx[3 * k + 2] = -1.0
        ubx[3 * k + 2] = 1.0
    for k in range(1, N + 1):
        lbx[3 * k] = -0.25

    x0 = np.zeros(n)
    x0[1] = 1.0

    return dict(
        x=w,
        f=J,
        g=ca.vertcat(*g),
        lbx=lbx,
        ubx=ubx,
        lbg=np.zeros(2 * N),
        ubg=np.zeros(2 * N),
        x0=x0,
    )


if __name__ == "__main__":
    p = build(4)
    print(p["x"].shape, p["g"].shape)
