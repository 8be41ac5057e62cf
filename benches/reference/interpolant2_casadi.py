"""Reference values for symx's 2-D lookup tables (symx/tests/interpolant2.rs), computed
with CasADi 3.8.2: `interpolant` on a 2-D rectilinear grid, 'linear' and 'bspline'.

Run: python3 benches/reference/interpolant2_casadi.py > benches/reference/results/interpolant2_casadi.txt
Prints, for each method and point (x, y), the value, the gradient [d/dx, d/dy] and the
Hessian entries [d2/dx2, d2/dxdy, d2/dy2] of the table, 17 significant digits. The data
are V[i, j] = sin(x_i) + cos(2 y_j) + 0.3 x_i y_j, passed to CasADi in column-major order
(x fastest), the order symx's Interpolant2 takes.
"""
import casadi as ca
import numpy as np

XG = [0.0, 0.5, 1.5, 2.0, 3.0]
YG = [-1.0, 0.0, 0.7, 2.0, 2.5]
POINTS = [(0.2, -0.5), (1.0, 1.0), (2.9, 1.9), (0.7, 2.2), (1.7, -0.9), (2.4, 0.35),
          (-0.5, 0.5), (3.5, 2.6), (1.0, 3.0)]


def fmt(v):
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


values = [np.sin(x) + np.cos(2 * y) + 0.3 * x * y for y in YG for x in XG]
print(f"x grid {fmt(XG)}")
print(f"y grid {fmt(YG)}")
print(f"values {fmt(values)}")
v = ca.SX.sym("v", 2)
for method in ["linear", "bspline"]:
    lut = ca.interpolant("lut", method, [XG, YG], values)
    e = lut(v)
    g = ca.gradient(e, v)
    h = ca.hessian(e, v)[0]
    f = ca.Function("f", [v], [e, g, h])
    for p in POINTS:
        val, grad, hess = f(p)
        hess = hess.full()
        print(f"{method} {fmt(p)}: value {float(val)!r} grad {fmt(grad.full().ravel())}"
              f" hess {fmt([hess[0, 0], hess[0, 1], hess[1, 1]])}")
