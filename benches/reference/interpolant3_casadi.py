"""Reference values for symx's n-D lookup tables on a 3-D grid (InterpolantN, tested in
symx/tests/interpolant_nd.rs), computed with CasADi 3.8.2: `interpolant` on a 3-D
rectilinear grid, 'linear' and 'bspline'.

Run: python3 benches/reference/interpolant3_casadi.py > benches/reference/results/interpolant3_casadi.txt
Prints, for each method and point (x, y, z), the value, the gradient and the upper
triangle of the Hessian [xx, xy, xz, yy, yz, zz] of the table, 17 significant digits.
The data are V[i, j, k] = sin(x_i) + cos(2 y_j) z_k + 0.3 x_i y_j z_k^2, passed to CasADi
in column-major order (x fastest), the order symx's InterpolantN takes.
"""
import casadi as ca
import numpy as np

XG = [0.0, 0.5, 1.5, 2.0]
YG = [-1.0, 0.0, 0.7, 2.0, 2.5]
ZG = [0.0, 0.4, 1.0, 1.3]
POINTS = [(0.2, -0.5, 0.1), (1.0, 1.0, 0.7), (1.9, 2.3, 1.2), (0.7, 0.35, 0.5),
          (-0.5, 0.5, 0.5), (1.0, 1.0, 1.5)]


def fmt(v):
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


values = [np.sin(x) + np.cos(2 * y) * z + 0.3 * x * y * z * z for z in ZG for y in YG for x in XG]
v = ca.SX.sym("v", 3)
for method in ["linear", "bspline"]:
    lut = ca.interpolant("lut", method, [XG, YG, ZG], values)
    e = lut(v)
    g = ca.gradient(e, v)
    h = ca.hessian(e, v)[0]
    f = ca.Function("f", [v], [e, g, h])
    for p in POINTS:
        val, grad, hess = f(p)
        hess = hess.full()
        upper = [hess[i, j] for i in range(3) for j in range(i, 3)]
        print(f"{method} {fmt(p)}: value {float(val)!r} grad {fmt(grad.full().ravel())}"
              f" hess {fmt(upper)}")
