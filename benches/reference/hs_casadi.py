"""Hock–Schittkowski problems in CasADi, solved with IPOPT (reference for nlp/tests/hs.rs).

Same formulations, bounds and starting points as the Rust suite in testkit/src/hs/problems.rs
(W. Hock, K. Schittkowski, "Test Examples for Nonlinear Programming Codes", LNEMS 187,
Springer 1981; optimal values as corrected in K. Schittkowski, "An updated set of 306
test problems for nonlinear programming with validated optimal solutions", 2008).

A constraint on a single variable is passed as a bound, as the Rust builder does
(nlp::Problem turns `lo <= x_i <= hi` rows into bounds).

Usage:
    python3 benches/reference/hs_casadi.py [name ...] > benches/reference/results/hs_ipopt.json

Prints one JSON object per line:
    {"name", "status", "success", "iterations", "objective", "f_star", "seconds"}
IPOPT options: tol 1e-8 (IPOPT's default), everything else default.

    python3 benches/reference/hs_casadi.py --compare OURS.json IPOPT.json

prints the Markdown comparison table of docs/performance.md from the JSON lines of
`cargo test --release -p nlp --test hs -- --ignored --nocapture hs_summary` and of this script.
"""
import json
import math
import sys
import time

import casadi as ca

INF = math.inf
SQRT2 = math.sqrt(2.0)
SQRT3 = math.sqrt(3.0)


class Hs:
    """A problem under construction: variables, bounds, start, objective, constraints."""

    def __init__(self, n, x0, lb=None, ub=None):
        self.x = ca.SX.sym("x", n)
        self.v = [self.x[i] for i in range(n)]
        self.x0 = [float(v) for v in (x0 if isinstance(x0, (list, tuple)) else [x0] * n)]
        self.lb = [float(v) for v in (lb if lb is not None else [-INF] * n)]
        self.ub = [float(v) for v in (ub if ub is not None else [INF] * n)]
        self.f = None
        self.g = []
        self.lbg = []
        self.ubg = []

    def ge(self, e, c=0.0):
        self.g.append(e)
        self.lbg.append(c)
        self.ubg.append(INF)

    def le(self, e, c=0.0):
        self.g.append(e)
        self.lbg.append(-INF)
        self.ubg.append(c)

    def eq(self, e, c=0.0):
        self.g.append(e)
        self.lbg.append(c)
        self.ubg.append(c)

    def bounded(self, lo, e, hi):
        self.g.append(e)
        self.lbg.append(lo)
        self.ubg.append(hi)


PROBLEMS = {}


def problem(f_star):
    def register(fn):
        PROBLEMS[fn.__name__] = (fn, f_star)
        return fn

    return register


def rosenbrock(x1, x2):
    return 100 * (x2 - x1**2) ** 2 + (1 - x1) ** 2


# ---------------------------------------------------------------- bounds only
@problem(0.0)
def hs001():
    p = Hs(2, [-2, 1], [-INF, -1.5])
    x1, x2 = p.v
    p.f = rosenbrock(x1, x2)
    return p


@problem(4.9412293)
def hs002():
    p = Hs(2, [-2, 1], [-INF, 1.5])
    x1, x2 = p.v
    p.f = rosenbrock(x1, x2)
    return p


@problem(0.0)
def hs003():
    p = Hs(2, [10, 1], [-INF, 0])
    x1, x2 = p.v
    p.f = x2 + 1e-5 * (x2 - x1) ** 2
    return p


@problem(8.0 / 3.0)
def hs004():
    p = Hs(2, [1.125, 0.125], [1, 0])
    x1, x2 = p.v
    p.f = (x1 + 1) ** 3 / 3 + x2
    return p


@problem(-SQRT3 / 2 - math.pi / 3)
def hs005():
    p = Hs(2, [0, 0], [-1.5, -3], [4, 3])
    x1, x2 = p.v
    p.f = ca.sin(x1 + x2) + (x1 - x2) ** 2 - 1.5 * x1 + 2.5 * x2 + 1
    return p


@problem(0.0)
def hs025():
    p = Hs(3, [100, 12.5, 3], [0.1, 0, 0], [100, 25.6, 5])
    x1, x2, x3 = p.v
    f = 0
    for i in range(1, 100):
        u = 25 + (-50 * math.log(0.01 * i)) ** (2.0 / 3.0)
        f += (-0.01 * i + ca.exp(-((u - x2) ** x3) / x1)) ** 2
    p.f = f
    return p


@problem(0.0)
def hs038():
    p = Hs(4, [-3, -1, -3, -1], [-10] * 4, [10] * 4)
    x1, x2, x3, x4 = p.v
    p.f = (
        100 * (x2 - x1**2) ** 2
        + (1 - x1) ** 2
        + 90 * (x4 - x3**2) ** 2
        + (1 - x3) ** 2
        + 10.1 * ((x2 - 1) ** 2 + (x4 - 1) ** 2)
        + 19.8 * (x2 - 1) * (x4 - 1)
    )
    return p


@problem(1.0)
def hs045():
    p = Hs(5, 2, [0] * 5, [1, 2, 3, 4, 5])
    x1, x2, x3, x4, x5 = p.v
    p.f = 2 - x1 * x2 * x3 * x4 * x5 / 120
    return p


@problem(-45.77846971)
def hs110():
    p = Hs(10, 9, [2.001] * 10, [9.999] * 10)
    s = 0
    prod = 1
    for xi in p.v:
        s += ca.log(xi - 2) ** 2 + ca.log(10 - xi) ** 2
        prod *= xi
    p.f = s - prod**0.2
    return p


# ---------------------------------------------------------------- equalities
@problem(0.0)
def hs006():
    p = Hs(2, [-1.2, 1])
    x1, x2 = p.v
    p.f = (1 - x1) ** 2
    p.eq(10 * (x2 - x1**2))
    return p


@problem(-SQRT3)
def hs007():
    p = Hs(2, [2, 2])
    x1, x2 = p.v
    p.f = ca.log(1 + x1**2) - x2
    p.eq((1 + x1**2) ** 2 + x2**2 - 4)
    return p


@problem(-1.0)
def hs008():
    p = Hs(2, [2, 1])
    x1, x2 = p.v
    p.f = ca.SX(-1.0)
    p.eq(x1**2 + x2**2 - 25)
    p.eq(x1 * x2 - 9)
    return p


@problem(-0.5)
def hs009():
    p = Hs(2, [0, 0])
    x1, x2 = p.v
    p.f = ca.sin(math.pi * x1 / 12) * ca.cos(math.pi * x2 / 16)
    p.eq(4 * x1 - 3 * x2)
    return p


@problem(0.0)
def hs026():
    p = Hs(3, [-2.6, 2, 2])
    x1, x2, x3 = p.v
    p.f = (x1 - x2) ** 2 + (x2 - x3) ** 4
    p.eq((1 + x2**2) * x1 + x3**4 - 3)
    return p


@problem(0.04)
def hs027():
    p = Hs(3, [2, 2, 2])
    x1, x2, x3 = p.v
    p.f = 0.01 * (x1 - 1) ** 2 + (x2 - x1**2) ** 2
    p.eq(x1 + x3**2 + 1)
    return p


@problem(0.0)
def hs028():
    p = Hs(3, [-4, 1, 1])
    x1, x2, x3 = p.v
    p.f = (x1 + x2) ** 2 + (x2 + x3) ** 2
    p.eq(x1 + 2 * x2 + 3 * x3 - 1)
    return p


@problem(-1.0)
def hs039():
    p = Hs(4, 2)
    x1, x2, x3, x4 = p.v
    p.f = -x1
    p.eq(x2 - x1**3 - x3**2)
    p.eq(x1**2 - x2 - x4**2)
    return p


@problem(-0.25)
def hs040():
    p = Hs(4, 0.8)
    x1, x2, x3, x4 = p.v
    p.f = -x1 * x2 * x3 * x4
    p.eq(x1**3 + x2**2 - 1)
    p.eq(x1**2 * x4 - x3)
    p.eq(x4**2 - x2)
    return p


@problem(28.0 - 10.0 * SQRT2)
def hs042():
    # x1 - 2 = 0 is a constraint on one variable: a (fixed) bound, as in the Rust builder.
    p = Hs(4, 1, [2, -INF, -INF, -INF], [2, INF, INF, INF])
    x1, x2, x3, x4 = p.v
    p.f = (x1 - 1) ** 2 + (x2 - 2) ** 2 + (x3 - 3) ** 2 + (x4 - 4) ** 2
    p.eq(x3**2 + x4**2 - 2)
    return p


@problem(0.0)
def hs046():
    p = Hs(5, [SQRT2 / 2, 1.75, 0.5, 2, 2])
    x1, x2, x3, x4, x5 = p.v
    p.f = (x1 - x2) ** 2 + (x3 - 1) ** 2 + (x4 - 1) ** 4 + (x5 - 1) ** 6
    p.eq(x1**2 * x4 + ca.sin(x4 - x5) - 1)
    p.eq(x2 + x3**4 * x4**2 - 2)
    return p


@problem(0.0)
def hs047():
    p = Hs(5, [2, SQRT2, -1, 2 - SQRT2, 0.5])
    x1, x2, x3, x4, x5 = p.v
    p.f = (x1 - x2) ** 2 + (x2 - x3) ** 3 + (x3 - x4) ** 4 + (x4 - x5) ** 4
    p.eq(x1 + x2**2 + x3**3 - 3)
    p.eq(x2 - x3**2 + x4 - 1)
    p.eq(x1 * x5 - 1)
    return p


@problem(0.0)
def hs048():
    p = Hs(5, [3, 5, -3, 2, -2])
    x1, x2, x3, x4, x5 = p.v
    p.f = (x1 - 1) ** 2 + (x2 - x3) ** 2 + (x4 - x5) ** 2
    p.eq(x1 + x2 + x3 + x4 + x5 - 5)
    p.eq(x3 - 2 * (x4 + x5) + 3)
    return p


@problem(0.0)
def hs049():
    p = Hs(5, [10, 7, 2, -3, 0.8])
    x1, x2, x3, x4, x5 = p.v
    p.f = (x1 - x2) ** 2 + (x3 - 1) ** 2 + (x4 - 1) ** 4 + (x5 - 1) ** 6
    p.eq(x1 + x2 + x3 + 4 * x4 - 7)
    p.eq(x3 + 5 * x5 - 6)
    return p


@problem(0.0)
def hs050():
    p = Hs(5, [35, -31, 11, 5, -5])
    x1, x2, x3, x4, x5 = p.v
    p.f = (x1 - x2) ** 2 + (x2 - x3) ** 2 + (x3 - x4) ** 4 + (x4 - x5) ** 2
    p.eq(x1 + 2 * x2 + 3 * x3 - 6)
    p.eq(x2 + 2 * x3 + 3 * x4 - 6)
    p.eq(x3 + 2 * x4 + 3 * x5 - 6)
    return p


@problem(0.0)
def hs051():
    p = Hs(5, [2.5, 0.5, 2, -1, 0.5])
    x1, x2, x3, x4, x5 = p.v
    p.f = (x1 - x2) ** 2 + (x2 + x3 - 2) ** 2 + (x4 - 1) ** 2 + (x5 - 1) ** 2
    p.eq(x1 + 3 * x2 - 4)
    p.eq(x3 + x4 - 2 * x5)
    p.eq(x2 - x5)
    return p


@problem(1859.0 / 349.0)
def hs052():
    p = Hs(5, 2)
    x1, x2, x3, x4, x5 = p.v
    p.f = (4 * x1 - x2) ** 2 + (x2 + x3 - 2) ** 2 + (x4 - 1) ** 2 + (x5 - 1) ** 2
    p.eq(x1 + 3 * x2)
    p.eq(x3 + x4 - 2 * x5)
    p.eq(x2 - x5)
    return p


@problem(176.0 / 43.0)
def hs053():
    p = Hs(5, 2, [-10] * 5, [10] * 5)
    x1, x2, x3, x4, x5 = p.v
    p.f = (x1 - x2) ** 2 + (x2 + x3 - 2) ** 2 + (x4 - 1) ** 2 + (x5 - 1) ** 2
    p.eq(x1 + 3 * x2)
    p.eq(x3 + x4 - 2 * x5)
    p.eq(x2 - x5)
    return p


@problem(-3.456)
def hs056():
    a = math.asin(math.sqrt(1 / 4.2))
    b = math.asin(math.sqrt(5 / 7.2))
    p = Hs(7, [1, 1, 1, a, a, a, b])
    x1, x2, x3, x4, x5, x6, x7 = p.v
    p.f = -x1 * x2 * x3
    p.eq(x1 - 4.2 * ca.sin(x4) ** 2)
    p.eq(x2 - 4.2 * ca.sin(x5) ** 2)
    p.eq(x3 - 4.2 * ca.sin(x6) ** 2)
    p.eq(x1 + 2 * x2 + 2 * x3 - 7.2 * ca.sin(x7) ** 2)
    return p


@problem(-143.6461422)
def hs061():
    p = Hs(3, 0)
    x1, x2, x3 = p.v
    p.f = 4 * x1**2 + 2 * x2**2 + 2 * x3**2 - 33 * x1 + 16 * x2 - 24 * x3
    p.eq(3 * x1 - 2 * x2**2 - 7)
    p.eq(4 * x1 - x3**2 - 11)
    return p


@problem(0.24150513)
def hs077():
    p = Hs(5, 2)
    x1, x2, x3, x4, x5 = p.v
    p.f = (x1 - 1) ** 2 + (x1 - x2) ** 2 + (x3 - 1) ** 2 + (x4 - 1) ** 4 + (x5 - 1) ** 6
    p.eq(x1**2 * x4 + ca.sin(x4 - x5) - 2 * SQRT2)
    p.eq(x2 + x3**4 * x4**2 - 8 - SQRT2)
    return p


@problem(-2.91970041)
def hs078():
    p = Hs(5, [-2, 1.5, 2, -1, -1])
    x1, x2, x3, x4, x5 = p.v
    p.f = x1 * x2 * x3 * x4 * x5
    p.eq(x1**2 + x2**2 + x3**2 + x4**2 + x5**2 - 10)
    p.eq(x2 * x3 - 5 * x4 * x5)
    p.eq(x1**3 + x2**3 + 1)
    return p


@problem(0.0787768209)
def hs079():
    p = Hs(5, 2)
    x1, x2, x3, x4, x5 = p.v
    p.f = (x1 - 1) ** 2 + (x1 - x2) ** 2 + (x2 - x3) ** 2 + (x3 - x4) ** 4 + (x4 - x5) ** 4
    p.eq(x1 + x2**2 + x3**3 - 2 - 3 * SQRT2)
    p.eq(x2 - x3**2 + x4 + 2 - 2 * SQRT2)
    p.eq(x1 * x5 - 2)
    return p


# ---------------------------------------------------------------- inequalities
@problem(-1.0)
def hs010():
    p = Hs(2, [-10, 10])
    x1, x2 = p.v
    p.f = x1 - x2
    p.ge(-3 * x1**2 + 2 * x1 * x2 - x2**2 + 1)
    return p


@problem(-8.498464223)
def hs011():
    p = Hs(2, [4.9, 0.1])
    x1, x2 = p.v
    p.f = (x1 - 5) ** 2 + x2**2 - 25
    p.ge(-(x1**2) + x2)
    return p


@problem(-30.0)
def hs012():
    p = Hs(2, [0, 0])
    x1, x2 = p.v
    p.f = 0.5 * x1**2 + x2**2 - x1 * x2 - 7 * x1 - 7 * x2
    p.ge(25 - 4 * x1**2 - x2**2)
    return p


@problem(1.0)
def hs013():
    p = Hs(2, [-2, -2], [0, 0])
    x1, x2 = p.v
    p.f = (x1 - 2) ** 2 + x2**2
    p.ge((1 - x1) ** 3 - x2)
    return p


@problem(9.0 - 2.875 * math.sqrt(7.0))
def hs014():
    p = Hs(2, [2, 2])
    x1, x2 = p.v
    p.f = (x1 - 2) ** 2 + (x2 - 1) ** 2
    p.ge(-0.25 * x1**2 - x2**2 + 1)
    p.eq(x1 - 2 * x2 + 1)
    return p


@problem(306.5)
def hs015():
    p = Hs(2, [-2, 1], [-INF, -INF], [0.5, INF])
    x1, x2 = p.v
    p.f = rosenbrock(x1, x2)
    p.ge(x1 * x2 - 1)
    p.ge(x1 + x2**2)
    return p


@problem(0.25)
def hs016():
    p = Hs(2, [-2, 1], [-0.5, -INF], [0.5, 1])
    x1, x2 = p.v
    p.f = rosenbrock(x1, x2)
    p.ge(x1 + x2**2)
    p.ge(x1**2 + x2)
    return p


@problem(1.0)
def hs017():
    p = Hs(2, [-2, 1], [-0.5, -INF], [0.5, 1])
    x1, x2 = p.v
    p.f = rosenbrock(x1, x2)
    p.ge(x2**2 - x1)
    p.ge(x1**2 - x2)
    return p


@problem(5.0)
def hs018():
    p = Hs(2, [2, 2], [2, 0], [50, 50])
    x1, x2 = p.v
    p.f = 0.01 * x1**2 + x2**2
    p.ge(x1 * x2 - 25)
    p.ge(x1**2 + x2**2 - 25)
    return p


def _hs019_f_star():
    x1 = 14.095
    x2 = 5.0 - math.sqrt(82.81 - (x1 - 6.0) ** 2)
    return (x1 - 10.0) ** 3 + (x2 - 20.0) ** 3


@problem(_hs019_f_star())
def hs019():
    p = Hs(2, [20.1, 5.84], [13, 0], [100, 100])
    x1, x2 = p.v
    p.f = (x1 - 10) ** 3 + (x2 - 20) ** 3
    p.ge((x1 - 5) ** 2 + (x2 - 5) ** 2 - 100)
    p.ge(-((x2 - 5) ** 2) - (x1 - 6) ** 2 + 82.81)
    return p


@problem(83.5 - 25.0 * SQRT3)
def hs020():
    p = Hs(2, [-2, 1], [-0.5, -INF], [0.5, INF])
    x1, x2 = p.v
    p.f = rosenbrock(x1, x2)
    p.ge(x1 + x2**2)
    p.ge(x1**2 + x2)
    p.ge(x1**2 + x2**2 - 1)
    return p


@problem(-99.96)
def hs021():
    p = Hs(2, [-1, -1], [2, -50], [50, 50])
    x1, x2 = p.v
    p.f = 0.01 * x1**2 + x2**2 - 100
    p.ge(10 * x1 - x2 - 10)
    return p


@problem(1.0)
def hs022():
    p = Hs(2, [2, 2])
    x1, x2 = p.v
    p.f = (x1 - 2) ** 2 + (x2 - 1) ** 2
    p.ge(-x1 - x2 + 2)
    p.ge(-(x1**2) + x2)
    return p


@problem(2.0)
def hs023():
    p = Hs(2, [3, 1], [-50, -50], [50, 50])
    x1, x2 = p.v
    p.f = x1**2 + x2**2
    p.ge(x1 + x2 - 1)
    p.ge(x1**2 + x2**2 - 1)
    p.ge(9 * x1**2 + x2**2 - 9)
    p.ge(x1**2 - x2)
    p.ge(x2**2 - x1)
    return p


@problem(-1.0)
def hs024():
    p = Hs(2, [1, 0.5], [0, 0])
    x1, x2 = p.v
    p.f = ((x1 - 3) ** 2 - 9) * x2**3 / (27 * SQRT3)
    p.ge(x1 / SQRT3 - x2)
    p.ge(x1 + SQRT3 * x2)
    p.ge(-x1 - SQRT3 * x2 + 6)
    return p


@problem(-16.0 * SQRT2)
def hs029():
    p = Hs(3, 1)
    x1, x2, x3 = p.v
    p.f = -x1 * x2 * x3
    p.ge(-(x1**2) - 2 * x2**2 - 4 * x3**2 + 48)
    return p


@problem(1.0)
def hs030():
    p = Hs(3, 1, [1, -10, -10], [10, 10, 10])
    x1, x2, x3 = p.v
    p.f = x1**2 + x2**2 + x3**2
    p.ge(x1**2 + x2**2 - 1)
    return p


@problem(6.0)
def hs031():
    p = Hs(3, 1, [-10, 1, -10], [10, 10, 1])
    x1, x2, x3 = p.v
    p.f = 9 * x1**2 + x2**2 + 9 * x3**2
    p.ge(x1 * x2 - 1)
    return p


@problem(1.0)
def hs032():
    p = Hs(3, [0.1, 0.7, 0.2], [0, 0, 0])
    x1, x2, x3 = p.v
    p.f = (x1 + 3 * x2 + x3) ** 2 + 4 * (x1 - x2) ** 2
    p.ge(6 * x2 + 4 * x3 - x1**3 - 3)
    p.eq(1 - x1 - x2 - x3)
    return p


@problem(SQRT2 - 6.0)
def hs033():
    p = Hs(3, [0, 0, 3], [0, 0, 0], [INF, INF, 5])
    x1, x2, x3 = p.v
    p.f = (x1 - 1) * (x1 - 2) * (x1 - 3) + x3
    p.ge(x3**2 - x1**2 - x2**2)
    p.ge(x1**2 + x2**2 + x3**2 - 4)
    return p


@problem(-math.log(math.log(10.0)))
def hs034():
    p = Hs(3, [0, 1.05, 2.9], [0, 0, 0], [100, 100, 10])
    x1, x2, x3 = p.v
    p.f = -x1
    p.ge(x2 - ca.exp(x1))
    p.ge(x3 - ca.exp(x2))
    return p


@problem(1.0 / 9.0)
def hs035():
    p = Hs(3, 0.5, [0, 0, 0])
    x1, x2, x3 = p.v
    p.f = 9 - 8 * x1 - 6 * x2 - 4 * x3 + 2 * x1**2 + 2 * x2**2 + x3**2 + 2 * x1 * x2 + 2 * x1 * x3
    p.ge(3 - x1 - x2 - 2 * x3)
    return p


@problem(-3300.0)
def hs036():
    p = Hs(3, 10, [0, 0, 0], [20, 11, 42])
    x1, x2, x3 = p.v
    p.f = -x1 * x2 * x3
    p.ge(72 - x1 - 2 * x2 - 2 * x3)
    return p


@problem(-3456.0)
def hs037():
    p = Hs(3, 10, [0, 0, 0], [42, 42, 42])
    x1, x2, x3 = p.v
    p.f = -x1 * x2 * x3
    p.ge(72 - x1 - 2 * x2 - 2 * x3)
    p.ge(x1 + 2 * x2 + 2 * x3)
    return p


@problem(-44.0)
def hs043():
    p = Hs(4, 0)
    x1, x2, x3, x4 = p.v
    p.f = x1**2 + x2**2 + 2 * x3**2 + x4**2 - 5 * x1 - 5 * x2 - 21 * x3 + 7 * x4
    p.ge(8 - x1**2 - x2**2 - x3**2 - x4**2 - x1 + x2 - x3 + x4)
    p.ge(10 - x1**2 - 2 * x2**2 - x3**2 - 2 * x4**2 + x1 + x4)
    p.ge(5 - 2 * x1**2 - x2**2 - x3**2 - 2 * x1 + x2 + x4)
    return p


@problem(-15.0)
def hs044():
    p = Hs(4, 0, [0] * 4)
    x1, x2, x3, x4 = p.v
    p.f = x1 - x2 - x3 - x1 * x3 + x1 * x4 + x2 * x3 - x2 * x4
    p.ge(8 - x1 - 2 * x2)
    p.ge(12 - 4 * x1 - x2)
    p.ge(12 - 3 * x1 - 4 * x2)
    p.ge(8 - 2 * x3 - x4)
    p.ge(8 - x3 - 2 * x4)
    p.ge(5 - x3 - x4)
    return p


@problem(6299.842428)
def hs064():
    p = Hs(3, 1, [1e-5] * 3)
    x1, x2, x3 = p.v
    p.f = 5 * x1 + 50000 / x1 + 20 * x2 + 72000 / x2 + 10 * x3 + 144000 / x3
    p.ge(1 - 4 / x1 - 32 / x2 - 120 / x3)
    return p


@problem(0.9535288567)
def hs065():
    p = Hs(3, [-5, 5, 0], [-4.5, -4.5, -5], [4.5, 4.5, 5])
    x1, x2, x3 = p.v
    p.f = (x1 - x2) ** 2 + (x1 + x2 - 10) ** 2 / 9 + (x3 - 5) ** 2
    p.ge(48 - x1**2 - x2**2 - x3**2)
    return p


@problem(0.5181632741)
def hs066():
    p = Hs(3, [0, 1.05, 2.9], [0, 0, 0], [100, 100, 10])
    x1, x2, x3 = p.v
    p.f = 0.2 * x3 - 0.8 * x1
    p.ge(x2 - ca.exp(x1))
    p.ge(x3 - ca.exp(x2))
    return p


@problem(-103.0 / 22.0)
def hs076():
    p = Hs(4, 0.5, [0] * 4)
    x1, x2, x3, x4 = p.v
    p.f = (
        x1**2 + 0.5 * x2**2 + x3**2 + 0.5 * x4**2 - x1 * x3 + x3 * x4 - x1 - 3 * x2 + x3 - x4
    )
    p.ge(5 - x1 - 2 * x2 - x3 - x4)
    p.ge(4 - 3 * x1 - x2 - 2 * x3 + x4)
    p.ge(x2 + 4 * x3 - 1.5)
    return p


@problem(680.6300573)
def hs100():
    p = Hs(7, [1, 2, 0, 4, 0, 1, 1])
    x1, x2, x3, x4, x5, x6, x7 = p.v
    p.f = (
        (x1 - 10) ** 2
        + 5 * (x2 - 12) ** 2
        + x3**4
        + 3 * (x4 - 11) ** 2
        + 10 * x5**6
        + 7 * x6**2
        + x7**4
        - 4 * x6 * x7
        - 10 * x6
        - 8 * x7
    )
    p.ge(127 - 2 * x1**2 - 3 * x2**4 - x3 - 4 * x4**2 - 5 * x5)
    p.ge(282 - 7 * x1 - 3 * x2 - 10 * x3**2 - x4 + x5)
    p.ge(196 - 23 * x1 - x2**2 - 6 * x6**2 + 8 * x7)
    p.ge(-4 * x1**2 - x2**2 + 3 * x1 * x2 - 2 * x3**2 - 5 * x6 + 11 * x7)
    return p


@problem(24.3062091)
def hs113():
    p = Hs(10, [2, 3, 5, 5, 1, 2, 7, 3, 6, 10])
    x1, x2, x3, x4, x5, x6, x7, x8, x9, x10 = p.v
    p.f = (
        x1**2
        + x2**2
        + x1 * x2
        - 14 * x1
        - 16 * x2
        + (x3 - 10) ** 2
        + 4 * (x4 - 5) ** 2
        + (x5 - 3) ** 2
        + 2 * (x6 - 1) ** 2
        + 5 * x7**2
        + 7 * (x8 - 11) ** 2
        + 2 * (x9 - 10) ** 2
        + (x10 - 7) ** 2
        + 45
    )
    p.ge(105 - 4 * x1 - 5 * x2 + 3 * x7 - 9 * x8)
    p.ge(-10 * x1 + 8 * x2 + 17 * x7 - 2 * x8)
    p.ge(8 * x1 - 2 * x2 - 5 * x9 + 2 * x10 + 12)
    p.ge(-3 * (x1 - 2) ** 2 - 4 * (x2 - 3) ** 2 - 2 * x3**2 + 7 * x4 + 120)
    p.ge(-5 * x1**2 - 8 * x2 - (x3 - 6) ** 2 + 2 * x4 + 40)
    p.ge(-0.5 * (x1 - 8) ** 2 - 2 * (x2 - 4) ** 2 - 3 * x5**2 + x6 + 30)
    p.ge(-(x1**2) - 2 * (x2 - 2) ** 2 + 2 * x1 * x2 - 14 * x5 + 6 * x6)
    p.ge(3 * x1 - 6 * x2 - 12 * (x9 - 8) ** 2 + 7 * x10)
    return p


# ---------------------------------------------------------------- mixed
@problem(17.0140173)
def hs071():
    p = Hs(4, [1, 5, 5, 1], [1] * 4, [5] * 4)
    x1, x2, x3, x4 = p.v
    p.f = x1 * x4 * (x1 + x2 + x3) + x3
    p.ge(x1 * x2 * x3 * x4 - 25)
    p.eq(x1**2 + x2**2 + x3**2 + x4**2 - 40)
    return p


@problem(29.894378)
def hs073():
    p = Hs(4, 1, [0] * 4)
    x1, x2, x3, x4 = p.v
    p.f = 24.55 * x1 + 26.75 * x2 + 39 * x3 + 40.5 * x4
    p.ge(2.3 * x1 + 5.6 * x2 + 11.1 * x3 + 1.3 * x4 - 5)
    p.ge(
        12 * x1
        + 11.9 * x2
        + 41.8 * x3
        + 52.1 * x4
        - 21
        - 1.645 * ca.sqrt(0.28 * x1**2 + 0.19 * x2**2 + 20.5 * x3**2 + 0.62 * x4**2)
    )
    p.eq(x1 + x2 + x3 + x4 - 1)
    return p


def _hs080_81(f_extra):
    p = Hs(5, [-2, 2, 2, -1, -1], [-2.3, -2.3, -3.2, -3.2, -3.2], [2.3, 2.3, 3.2, 3.2, 3.2])
    x1, x2, x3, x4, x5 = p.v
    p.f = ca.exp(x1 * x2 * x3 * x4 * x5) + f_extra(x1, x2)
    p.eq(x1**2 + x2**2 + x3**2 + x4**2 + x5**2 - 10)
    p.eq(x2 * x3 - 5 * x4 * x5)
    p.eq(x1**3 + x2**3 + 1)
    return p


@problem(0.0539498478)
def hs080():
    return _hs080_81(lambda x1, x2: 0)


@problem(0.0539498478)
def hs081():
    return _hs080_81(lambda x1, x2: -0.5 * (x1**3 + x2**3 + 1) ** 2)


@problem(7049.24802)
def hs106():
    p = Hs(
        8,
        [5000, 5000, 5000, 200, 350, 150, 225, 425],
        [100, 1000, 1000, 10, 10, 10, 10, 10],
        [10000, 10000, 10000, 1000, 1000, 1000, 1000, 1000],
    )
    x1, x2, x3, x4, x5, x6, x7, x8 = p.v
    p.f = x1 + x2 + x3
    p.ge(1 - 0.0025 * (x4 + x6))
    p.ge(1 - 0.0025 * (x5 + x7 - x4))
    p.ge(1 - 0.01 * (x8 - x5))
    p.ge(x1 * x6 - 833.33252 * x4 - 100 * x1 + 83333.333)
    p.ge(x2 * x7 - 1250 * x5 - x2 * x4 + 1250 * x4)
    p.ge(x3 * x8 - 1250000 - x3 * x5 + 2500 * x5)
    return p


@problem(-SQRT3 / 2)
def hs108():
    p = Hs(9, 1, [-INF] * 8 + [0])
    x1, x2, x3, x4, x5, x6, x7, x8, x9 = p.v
    p.f = -0.5 * (x1 * x4 - x2 * x3 + x3 * x9 - x5 * x9 + x5 * x8 - x6 * x7)
    p.ge(1 - x3**2 - x4**2)
    p.ge(1 - x5**2 - x6**2)
    p.ge(1 - (x1 - x5) ** 2 - (x2 - x6) ** 2)
    p.ge(1 - (x1 - x7) ** 2 - (x2 - x8) ** 2)
    p.ge(1 - (x3 - x5) ** 2 - (x4 - x6) ** 2)
    p.ge(1 - (x3 - x7) ** 2 - (x4 - x8) ** 2)
    p.ge(x3 * x9)
    p.ge(x5 * x8 - x6 * x7)
    p.ge(1 - x9**2)
    p.ge(1 - x7**2 - (x8 - x9) ** 2)
    p.ge(1 - x1**2 - (x2 - x9) ** 2)
    p.ge(x1 * x4 - x2 * x3)
    p.ge(-x5 * x9)
    return p


@problem(-1768.80696)
def hs114():
    p = Hs(
        10,
        [1745, 12000, 110, 3048, 1974, 89.2, 92.8, 8, 3.6, 145],
        [1e-5, 1e-5, 1e-5, 1e-5, 1e-5, 85, 90, 3, 1.2, 145],
        [2000, 16000, 120, 5000, 2000, 93, 95, 12, 4, 162],
    )
    x1, x2, x3, x4, x5, x6, x7, x8, x9, x10 = p.v
    a, b = 0.99, 0.9
    g1 = 35.82 - 0.222 * x10 - b * x9
    g2 = -133 + 3 * x7 - a * x10
    g5 = 1.12 * x1 + 0.13167 * x1 * x8 - 0.00667 * x1 * x8**2 - a * x4
    g6 = 57.425 + 1.098 * x8 - 0.038 * x8**2 + 0.325 * x6 - a * x7
    p.f = 5.04 * x1 + 0.035 * x2 + 10 * x3 + 3.36 * x5 - 0.063 * x4 * x7
    p.ge(g1)
    p.ge(g2)
    p.ge(-g1 + x9 * (1 / b - b))
    p.ge(-g2 + (1 / a - a) * x10)
    p.ge(g5)
    p.ge(g6)
    p.ge(-g5 + (1 / a - a) * x4)
    p.ge(-g6 + (1 / a - a) * x7)
    p.eq(1.22 * x4 - x1 - x5)
    p.eq(98000 * x3 / (x4 * x9 + 1000 * x3) - x6)
    p.eq((x2 + x5) / x1 - x8)
    return p


@problem(97.5874731)
def hs116():
    p = Hs(
        13,
        [0.5, 0.8, 0.9, 0.1, 0.14, 0.5, 489, 80, 650, 450, 150, 150, 150],
        [0.1, 0.1, 0.1, 1e-4, 0.1, 0.1, 0.1, 0.1, 500, 0.1, 1, 1e-4, 1e-4],
        [1, 1, 1, 0.1, 0.9, 0.9, 1000, 1000, 1000, 500, 150, 150, 150],
    )
    x1, x2, x3, x4, x5, x6, x7, x8, x9, x10, x11, x12, x13 = p.v
    a, b, c, d, e, f = 0.002, 1.262626, 1.231059, 0.03475, 0.975, 0.00975
    p.f = x11 + x12 + x13
    p.ge(x3 - x2)
    p.ge(x2 - x1)
    p.ge(1 - a * x7 + a * x8)
    p.ge(x11 + x12 + x13 - 50)
    p.ge(x13 - b * x10 + c * x3 * x10)
    p.ge(x5 - d * x2 - e * x2 * x5 + f * x2**2)
    p.ge(x6 - d * x3 - e * x3 * x6 + f * x3**2)
    p.ge(x4 - d * x1 - e * x1 * x4 + f * x1**2)
    p.ge(x12 - b * x9 + c * x2 * x9)
    p.ge(x11 - b * x8 + c * x1 * x8)
    p.ge(x5 * x7 - x1 * x8 - x4 * x7 + x4 * x8)
    p.ge(1 - a * (x2 * x9 + x5 * x8 - x1 * x8 - x6 * x9) - x5 - x6)
    p.ge(x2 * x9 - x3 * x10 - x6 * x9 - 500 * x2 + 500 * x6 + x2 * x10)
    p.ge(x2 - 0.9 - a * (x2 * x10 - x3 * x10))
    p.le(x11 + x12 + x13, 250)
    return p


@problem(664.82045)
def hs118():
    lb = [8, 43, 3] + [0] * 12
    ub = [21, 57, 16] + [90, 120, 60] * 4
    p = Hs(15, [20, 55, 15] + [20, 60, 20] * 4, lb, ub)
    x = p.v
    f = 0
    for k in range(5):
        a, b, c = x[3 * k], x[3 * k + 1], x[3 * k + 2]
        f += 2.3 * a + 1e-4 * a**2 + 1.7 * b + 1e-4 * b**2 + 2.2 * c + 1.5e-4 * c**2
    p.f = f
    for j in range(1, 5):
        p.bounded(0, x[3 * j] - x[3 * j - 3] + 7, 13)
        p.bounded(0, x[3 * j + 1] - x[3 * j - 2] + 7, 14)
        p.bounded(0, x[3 * j + 2] - x[3 * j - 1] + 7, 13)
    p.ge(x[0] + x[1] + x[2] - 60)
    p.ge(x[3] + x[4] + x[5] - 50)
    p.ge(x[6] + x[7] + x[8] - 70)
    p.ge(x[9] + x[10] + x[11] - 85)
    p.ge(x[12] + x[13] + x[14] - 100)
    return p


def solve(name, extra_opts=None):
    """IPOPT on one problem: tol 1e-8, IPOPT's defaults otherwise, plus `extra_opts`."""
    build, f_star = PROBLEMS[name]
    p = build()
    nlp = {"x": p.x, "f": p.f}
    if p.g:
        nlp["g"] = ca.vertcat(*p.g)
    opts = {"ipopt.tol": 1e-8, "ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes"}
    opts.update(extra_opts or {})
    solver = ca.nlpsol(name, "ipopt", nlp, opts)
    args = {"x0": p.x0, "lbx": p.lb, "ubx": p.ub}
    if p.g:
        args["lbg"] = p.lbg
        args["ubg"] = p.ubg
    t0 = time.perf_counter()
    res = solver(**args)
    seconds = time.perf_counter() - t0
    stats = solver.stats()
    return {
        "name": name,
        "status": stats["return_status"],
        "success": bool(stats["success"]),
        "iterations": int(stats["iter_count"]),
        "objective": float(res["f"]),
        "f_star": f_star,
        "seconds": seconds,
    }


def compare(ours_path, ipopt_path):
    import statistics

    def load(path):
        with open(path) as f:
            return {r["name"]: r for r in (json.loads(line) for line in f if line.startswith("{"))}

    ours, ipopt = load(ours_path), load(ipopt_path)
    print("| problem | f* | symnlp status | iter | IPOPT status | iter | objective (symnlp) | Δf vs IPOPT (rel.) |")
    print("|---|---:|---|---:|---|---:|---:|---:|")
    for name, o in ours.items():
        i = ipopt[name]
        f = o.get("objective", math.nan)
        diff = abs(f - i["objective"]) / max(1.0, abs(i["objective"]))
        status = o["status"] + ("" if o.get("matches") in (None, "f*") else f" ({o['matches']} min.)")
        print(
            f"| {name} | {o['f_star']:.10g} | {status} | {o.get('iterations', '–')} "
            f"| {i['status']} | {i['iterations']} | {f:.10g} | {diff:.1e} |"
        )
    it_o = [o["iterations"] for o in ours.values() if "iterations" in o]
    it_i = [i["iterations"] for i in ipopt.values()]
    print()
    print(f"median iterations: symnlp {statistics.median(it_o)}, IPOPT {statistics.median(it_i)}; "
          f"total: symnlp {sum(it_o)}, IPOPT {sum(it_i)}")
    fewer = sum(ours[n]["iterations"] < ipopt[n]["iterations"] for n in ours)
    more = sum(ours[n]["iterations"] > ipopt[n]["iterations"] for n in ours)
    print(f"fewer iterations than IPOPT on {fewer}, as many on {len(ours) - fewer - more}, more on {more}")
    print(f"solve time, sum over the suite: symnlp {sum(o['seconds'] for o in ours.values()):.4f} s, "
          f"IPOPT via CasADi {sum(i['seconds'] for i in ipopt.values()):.4f} s")


def main():
    if sys.argv[1:2] == ["--compare"]:
        compare(sys.argv[2], sys.argv[3])
        return
    names = sys.argv[1:] or sorted(PROBLEMS)
    for name in names:
        print(json.dumps(solve(name)), flush=True)


if __name__ == "__main__":
    main()
