"""Reference values for symx's operations (symx/tests/ops.rs), computed with CasADi 3.8.2 SX.

Run: python3 benches/reference/symx_ops_casadi.py > benches/reference/results/symx_ops_casadi.txt
Prints Rust-ready rows: for each case the value, gradient and (scalar operations) the
Hessian of a scalar expression at a fixed point, with 17 significant digits. The test file
copies these numbers; the case names are the same on both sides.
"""
import casadi as ca


def fmt(v):
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


def emit(name, e, v, point):
    """Value, gradient and Hessian (column-major, dense) of scalar e(v) at point."""
    g = ca.gradient(e, v)
    h = ca.hessian(e, v)[0]
    f = ca.Function("f", [v], [e, g, ca.vec(h)])
    val, grad, hess = f(point)
    print(f"{name}: value {float(val)!r} grad {fmt(ca.vec(grad).full().ravel())}"
          f" hess {fmt(ca.vec(hess).full().ravel())}")


def emit_vec(name, out, v, point):
    """Entries (column-major) of a matrix expression at point, and the gradient of the
    weighted sum sum_k (k+1) * out_k (k in column-major order)."""
    o = ca.vec(out)
    w = ca.DM([k + 1.0 for k in range(o.numel())])
    s = ca.dot(w, o)
    f = ca.Function("f", [v], [o, ca.gradient(s, v)])
    val, grad = f(point)
    print(f"{name}: value {fmt(val.full().ravel())} grad {fmt(grad.full().ravel())}")


x = ca.SX.sym("x")
y = ca.SX.sym("y")
z = ca.SX.sym("z")
xy = ca.vertcat(x, y)
xyz = ca.vertcat(x, y, z)

print("# scalar operations: value, gradient, Hessian")
unary = {
    "floor": ca.floor, "ceil": ca.ceil, "erf": ca.erf, "asinh": ca.asinh,
    "acosh": ca.acosh, "atanh": ca.atanh, "log1p": ca.log1p, "expm1": ca.expm1,
}
points = {
    "floor": [2.7, -1.3], "ceil": [2.7, -1.3], "erf": [0.3, -1.2], "asinh": [0.7, -2.0],
    "acosh": [1.5, 3.0], "atanh": [0.3, -0.8], "log1p": [1e-3, 2.0], "expm1": [1e-3, -1.5],
}
for name, op in unary.items():
    for k, p in enumerate(points[name]):
        # Compose with a polynomial so that the chain rule and second derivatives show.
        emit(f"{name}_{k}", op(x) * (1 + x * x), x, p)
for k, p in enumerate([[5.3, 2.0], [-5.3, 2.0], [7.5, -2.2]]):
    emit(f"fmod_{k}", ca.fmod(x, y) * y, xy, p)
for k, p in enumerate([[3.0, 4.0], [-1.2, 0.5]]):
    emit(f"hypot_{k}", ca.hypot(x, y) * x, xy, p)
for k, p in enumerate([[1.0, 2.0, 3.0], [100.0, 101.0, 99.0], [-3.0, 0.5, 0.25]]):
    emit(f"logsumexp_{k}", ca.logsumexp(xyz) * x, xyz, p)

print("# matrix operations: entries (column-major) and gradient of sum_k (k+1) out_k")
A = ca.SX.sym("A", 3, 3)
B = ca.SX.sym("B", 3, 2)
vA = ca.vec(A)
vAB = ca.vertcat(ca.vec(A), ca.vec(B))
a_full = [2.0, 0.5, -1.0, 1.0, 3.0, 0.2, -0.4, 1.1, 4.0]   # column-major
a_zero_pivot = [0.0, 1.0, 4.0, 1.0, 0.0, 5.0, 2.0, 3.0, 0.0]  # [[0,1,2],[1,0,3],[4,5,0]]
b_vals = [1.0, -2.0, 0.5, 3.0, 0.0, -1.0]
emit_vec("solve_full", ca.solve(A, B), vAB, a_full + b_vals)
emit_vec("solve_zero_pivot", ca.solve(A, B), vAB, a_zero_pivot + b_vals)
emit_vec("inverse", ca.inv(A), vA, a_full)
emit_vec("det3", ca.det(A), vA, a_full)
A4 = ca.SX.sym("A4", 4, 4)
a4 = [2.0, 0.5, -1.0, 0.3, 1.0, 3.0, 0.2, -0.7, -0.4, 1.1, 4.0, 0.9, 0.6, -0.2, 0.8, 2.5]
emit_vec("det4", ca.det(A4), ca.vec(A4), a4)
# Triangular systems (structural zeros): upper and lower.
U = ca.SX.zeros(3, 3)
L = ca.SX.zeros(3, 3)
for j in range(3):
    for i in range(3):
        if i <= j:
            U[i, j] = A[i, j]
        if i >= j:
            L[i, j] = A[i, j]
emit_vec("solve_upper", ca.solve(U, B), vAB, a_full + b_vals)
emit_vec("solve_lower", ca.solve(L, B), vAB, a_full + b_vals)
M = ca.SX.sym("M", 2, 3)
m_vals = [1.5, -2.0, 0.3, 4.0, -0.1, 2.2]
emit_vec("norm_1", ca.norm_1(M), ca.vec(M), m_vals)
emit_vec("norm_inf", ca.norm_inf(M), ca.vec(M), m_vals)
emit_vec("norm_fro", ca.norm_fro(M), ca.vec(M), m_vals)
N = ca.SX.sym("N", 2, 2)
n_vals = [0.5, 1.0, -1.0, 2.0]
MN = ca.vertcat(ca.vec(M), ca.vec(N))
emit_vec("kron", ca.kron(M, N), MN, m_vals + n_vals)
emit_vec("reshape", ca.reshape(M, 3, 2), ca.vec(M), m_vals)
emit_vec("repmat", ca.repmat(N, 2, 3), ca.vec(N), n_vals)
emit_vec("diagcat", ca.diagcat(M, N), MN, m_vals + n_vals)

print("# interpolants: value, derivative, second derivative at points")
grid = [0.0, 1.0, 2.0, 3.0, 4.0, 5.5, 7.0]
vals = [0.0, 1.0, 4.0, 2.0, 1.0, 3.0, -1.0]
ts = [-1.0, 0.5, 1.0 + 1e-9, 2.5, 3.7, 5.0, 6.9, 8.0]
for kind in ["linear", "bspline"]:
    lut = ca.interpolant("lut", kind, [grid], vals)
    e = lut(x)
    d = ca.jacobian(e, x)
    f = ca.Function("f", [x], [e, d])
    out = [f(t) for t in ts]
    print(f"{kind}: t {fmt(ts)}")
    print(f"{kind}: value {fmt([o[0] for o in out])}")
    print(f"{kind}: deriv {fmt([o[1] for o in out])}")
    if kind == "bspline":
        h = ca.Function("h", [x], [ca.jacobian(d, x)])
        print(f"{kind}: deriv2 {fmt([h(t) for t in ts])}")
