"""The transcriptions of nlp::ocp (nlp/src/ocp/transcription.rs) written with CasADi SX, so
IPOPT solves the identical NLP as symnlp: same variables (grid states X, controls U,
free final time T, collocation states Xc), same bounds, same constraint rows (up to the
side a relation is moved to) and the same objective. Used by ocp_examples.py.

An OCP is a dict:
  nx, nu; f(x, u) -> xdot (lists of SX); l(x, u) -> stage cost or None;
  phi(xN, T) -> terminal cost or None; x_lb, x_ub, u_lb, u_ub (lists);
  x0, xf (lists or None); path: list of c(x, u) -> (exprs, lb, ub), imposed at k = 0..N
  with u_min(k, N-1); boundary: list of b(x0, xN, T) -> (exprs, lb, ub);
  horizon: ("fixed", T) or ("free", lower, upper, guess);
  guess_x(t) -> list, guess_u(t) -> list (or None: zeros).
A method is ("ms", A, b, M) for an explicit Runge-Kutta tableau (A lower triangular, b
weights) with M steps per interval, or ("colloc", "legendre" | "radau", d).
"""
import casadi as ca
import numpy as np


def rk_integrate(rhs, z, h, A, b, M):
    dt = h / M
    for _ in range(M):
        k = []
        for i in range(len(b)):
            zi = z
            for j in range(i):
                if A[i][j] != 0.0:
                    zi = zi + (dt * A[i][j]) * k[j]
            k.append(rhs(zi))
        s = None
        for ki, bi in zip(k, b):
            if bi != 0.0:
                s = bi * ki if s is None else s + bi * ki
        z = z + dt * s
    return z


def collocation_coefficients(scheme, d):
    """CasADi's direct_collocation.py coefficient loop."""
    tau = np.append(0, ca.collocation_points(d, scheme))
    C = np.zeros((d + 1, d + 1))
    D = np.zeros(d + 1)
    B = np.zeros(d + 1)
    for j in range(d + 1):
        p = np.poly1d([1])
        for r in range(d + 1):
            if r != j:
                p *= np.poly1d([1, -tau[r]]) / (tau[j] - tau[r])
        D[j] = p(1.0)
        pder = np.polyder(p)
        for r in range(d + 1):
            C[j, r] = pder(tau[r])
        B[j] = np.polyint(p)(1.0)
    return tau, C, D, B


def solve(ocp, method, N, ipopt_options=None):
    nx, nu = ocp["nx"], ocp["nu"]
    X = ca.SX.sym("X", nx, N + 1)
    U = ca.SX.sym("U", nu, N)
    hor = ocp["horizon"]
    free = hor[0] == "free"
    T = ca.SX.sym("T") if free else hor[1]
    t_guess = hor[3] if free else hor[1]
    h = T / N
    col = lambda M, k: [M[i, k] for i in range(M.shape[0])]
    g, lbg, ubg = [], [], []
    J = 0
    Xc = None

    def add(exprs, lb, ub):
        g.extend(exprs)
        lbg.extend(lb if isinstance(lb, list) else [lb] * len(exprs))
        ubg.extend(ub if isinstance(ub, list) else [ub] * len(exprs))

    if method[0] == "ms":
        _, A, b, M = method
        for k in range(N):
            uk = col(U, k)

            def rhs(z):
                xs = [z[i] for i in range(nx)]
                dz = list(ocp["f"](xs, uk))
                if ocp["l"] is not None:
                    dz.append(ocp["l"](xs, uk))
                return ca.vertcat(*dz)

            z0 = col(X, k) + ([0] if ocp["l"] is not None else [])
            z = rk_integrate(rhs, ca.vertcat(*z0), h, A, b, M)
            if ocp["l"] is not None:
                J = J + z[nx]
            add([X[i, k + 1] - z[i] for i in range(nx)], 0, 0)
    else:
        _, scheme, d = method
        tau, C, D, B = collocation_coefficients(scheme, d)
        Xc = ca.SX.sym("Xc", nx, N * d)
        for k in range(N):
            uk = col(U, k)
            xk = ca.vertcat(*col(X, k))
            pts = [ca.vertcat(*col(Xc, k * d + j)) for j in range(d)]
            for j in range(1, d + 1):
                xp = C[0, j] * xk
                for r in range(1, d + 1):
                    xp = xp + C[r, j] * pts[r - 1]
                fj = ca.vertcat(*ocp["f"]([pts[j - 1][i] for i in range(nx)], uk))
                add(ca.vertsplit(h * fj - xp), 0, 0)
                if ocp["l"] is not None:
                    J = J + B[j] * ocp["l"]([pts[j - 1][i] for i in range(nx)], uk) * h
            x_end = D[0] * xk
            for r in range(1, d + 1):
                x_end = x_end + D[r] * pts[r - 1]
            add([X[i, k + 1] - x_end[i] for i in range(nx)], 0, 0)
    for c in ocp.get("path", []):
        for k in range(N + 1):
            e, lb, ub = c(col(X, k), col(U, min(k, N - 1)))
            add(e, lb, ub)
    for bnd in ocp.get("boundary", []):
        e, lb, ub = bnd(col(X, 0), col(X, N), T)
        add(e, lb, ub)
    if ocp.get("phi") is not None:
        J = J + ocp["phi"](col(X, N), T)

    # Variables, bounds and guesses in symnlp's order: X, U, T, Xc.
    w, lbw, ubw, w0 = [], [], [], []
    gx = ocp.get("guess_x") or (lambda t: [0.0] * nx)
    gu = ocp.get("guess_u") or (lambda t: [0.0] * nu)
    for k in range(N + 1):
        for i in range(nx):
            lo, hi = ocp["x_lb"][i], ocp["x_ub"][i]
            if ocp.get("x0") is not None and k == 0:
                lo, hi = max(lo, ocp["x0"][i]), min(hi, ocp["x0"][i])
            if ocp.get("xf") is not None and k == N:
                lo, hi = max(lo, ocp["xf"][i]), min(hi, ocp["xf"][i])
            w.append(X[i, k]); lbw.append(lo); ubw.append(hi)
            w0.append(gx(k * t_guess / N)[i])
    for k in range(N):
        for j in range(nu):
            w.append(U[j, k]); lbw.append(ocp["u_lb"][j]); ubw.append(ocp["u_ub"][j])
            w0.append(gu(k * t_guess / N)[j])
    if free:
        w.append(T); lbw.append(hor[1]); ubw.append(hor[2]); w0.append(hor[3])
    if Xc is not None:
        for k in range(N):
            for j in range(d):
                for i in range(nx):
                    w.append(Xc[i, k * d + j]); lbw.append(ocp["x_lb"][i]); ubw.append(ocp["x_ub"][i])
                    w0.append(gx((k + tau[j + 1]) * t_guess / N)[i])
    opts = {"print_time": False, "ipopt": {"print_level": 0, "sb": "yes", "tol": 1e-8}}
    if ipopt_options:
        opts["ipopt"].update(ipopt_options)
    solver = ca.nlpsol("s", "ipopt", {"x": ca.vertcat(*w), "f": J, "g": ca.vertcat(*g)}, opts)
    sol = solver(x0=w0, lbx=lbw, ubx=ubw, lbg=lbg, ubg=ubg)
    st = solver.stats()
    wopt = np.array(sol["x"]).ravel()
    t_opt = float(wopt[(N + 1) * nx + N * nu]) if free else float(T)
    return {"objective": float(sol["f"]), "T": t_opt, "iterations": st["iter_count"],
            "status": st["return_status"]}
