"""Test problems written once against an Opti-like interface, so the same formulation is
built in symnlp (``symnlp.Problem``) and in CasADi (``casadi.Opti`` via ``CasadiOpti``).

Each ``build_*(pb, m)`` takes a problem object and the math module (``symnlp`` or
``casadi``) and returns the decision variable(s) of interest.
"""
import math

import numpy as np


class CasadiOpti:
    """casadi.Opti behind symnlp.Problem's method names (the reference side)."""

    def __init__(self):
        import casadi

        self.ca = casadi
        self.opti = casadi.Opti()
        self.f = None

    def variable(self, name, n=1):
        return self.opti.variable(n)

    def parameter(self, name, n=1):
        return self.opti.parameter(n)

    def minimize(self, f):
        self.f = f
        self.opti.minimize(f)

    def subject_to(self, c, name=None):
        self.opti.subject_to(c)

    def bounded(self, lo, x, hi):
        return self.opti.bounded(lo, x, hi)

    def set_initial(self, x, v):
        self.opti.set_initial(x, v)

    def set_value(self, p, v):
        self.opti.set_value(p, v)

    def solve(self, exact_bounds=False):
        """IPOPT at tol 1e-10; `exact_bounds` turns off its bound relaxation (by default
        every bound is loosened by 1e-8 relative, which moves an optimum with active
        bounds by about the sum of their multipliers times 1e-8)."""
        opts = {"print_level": 0, "sb": "yes", "tol": 1e-10}
        if exact_bounds:
            opts["bound_relax_factor"] = 0.0
        self.opti.solver("ipopt", {"print_time": False}, opts)
        sol = self.opti.solve()
        return float(sol.value(self.f)), sol


def build_hs071(pb, m):
    """Hock & Schittkowski problem 71; published optimum 17.0140173."""
    x = pb.variable("x", 4)
    pb.minimize(x[0] * x[3] * (x[0] + x[1] + x[2]) + x[2])
    pb.subject_to(x[0] * x[1] * x[2] * x[3] >= 25)
    pb.subject_to(x[0] ** 2 + x[1] ** 2 + x[2] ** 2 + x[3] ** 2 == 40)
    pb.subject_to(pb.bounded(1, x, 5))
    pb.set_initial(x, [1, 5, 5, 1])
    return x


def build_rosenbrock_disc(pb, m):
    """Rosenbrock inside the disc x0² + x1² ≤ 1.5 (docs/problem.md's example)."""
    x = pb.variable("x", 2)
    pb.minimize((1 - x[0]) ** 2 + 100 * (x[1] - x[0] ** 2) ** 2)
    pb.subject_to(x[0] ** 2 + x[1] ** 2 <= 1.5)
    pb.set_initial(x, [-1.2, 1.0])
    return x


def build_hs035(pb, m):
    """Hock & Schittkowski problem 35; published optimum 1/9."""
    x = pb.variable("x", 3)
    pb.minimize(
        9 - 8 * x[0] - 6 * x[1] - 4 * x[2] + 2 * x[0] ** 2 + 2 * x[1] ** 2 + x[2] ** 2
        + 2 * x[0] * x[1] + 2 * x[0] * x[2]
    )
    pb.subject_to(x >= 0)
    pb.subject_to(x[0] + x[1] + 2 * x[2] <= 3)
    pb.set_initial(x, [0.5, 0.5, 0.5])
    return x


def build_chain(pb, m, n=20, length=1.25):
    """Hanging chain of n masses between two endpoints given as parameters: minimum
    potential energy, each link at most length / (n - 1) long."""
    xs = pb.variable("px", n)
    ys = pb.variable("py", n)
    ends = pb.parameter("ends", 4)
    pb.set_value(ends, [0.0, 1.0, 1.0, 0.5])
    pb.minimize(sum(ys[i] for i in range(n)))
    seg = length / (n - 1)
    for i in range(n - 1):
        pb.subject_to((xs[i + 1] - xs[i]) ** 2 + (ys[i + 1] - ys[i]) ** 2 <= seg ** 2)
    pb.subject_to(xs[0] == ends[0])
    pb.subject_to(ys[0] == ends[1])
    pb.subject_to(xs[n - 1] == ends[2])
    pb.subject_to(ys[n - 1] == ends[3])
    pb.set_initial(xs, list(np.linspace(0, 1, n)))
    pb.set_initial(ys, list(np.linspace(1, 0.5, n)))
    return ys, ends


def build_hs038(pb, m):
    """Hock & Schittkowski problem 38 (Wood/Colville); published optimum 0."""
    x = pb.variable("x", 4)
    pb.minimize(
        100 * (x[1] - x[0] ** 2) ** 2 + (1 - x[0]) ** 2 + 90 * (x[3] - x[2] ** 2) ** 2
        + (1 - x[2]) ** 2 + 10.1 * ((x[1] - 1) ** 2 + (x[3] - 1) ** 2)
        + 19.8 * (x[1] - 1) * (x[3] - 1)
    )
    pb.subject_to(pb.bounded(-10, x, 10))
    pb.set_initial(x, [-3, -1, -3, -1])
    return x


def build_trig(pb, m):
    """MATLAB fmincon's classic example (an exponential objective): min exp(x0)·(4x0²
    + 2x1² + 4x0x1 + 2x1 + 1) s.t. x0x1 − x0 − x1 ≤ −1.5, x0x1 ≥ −10; optimum ≈ 0.0236
    at (−9.5474, 1.0474)."""
    x = pb.variable("x", 2)
    pb.minimize(m.exp(x[0]) * (4 * x[0] ** 2 + 2 * x[1] ** 2 + 4 * x[0] * x[1] + 2 * x[1] + 1))
    pb.subject_to(x[0] * x[1] - x[0] - x[1] <= -1.5)
    pb.subject_to(x[0] * x[1] >= -10)
    pb.set_initial(x, [-1, 1])
    return x


PROBLEMS = {
    "hs071": build_hs071,
    "rosenbrock_disc": build_rosenbrock_disc,
    "hs035": build_hs035,
    "chain20": lambda pb, m: build_chain(pb, m)[0],
    "hs038": build_hs038,
    "fmincon_example": build_trig,
}

# Published optima (Hock & Schittkowski, "Test Examples for Nonlinear Programming Codes",
# 1981: problems 35, 38, 71).
PUBLISHED = {"hs071": 17.0140173, "hs035": 1.0 / 9.0, "hs038": 0.0}

assert math.isfinite(PUBLISHED["hs035"])
