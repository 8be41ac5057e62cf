"""IPOPT's optima (CasADi 3.8.2 + IPOPT 3.14.19) of the OCP examples of symnlp, each on the
identical transcription (ocp_transcription.py mirrors nlp/src/ocp/transcription.rs). The
problem data here and in the Rust examples must stay in sync:

  vdp_multiple_shooting  examples/src/vdp_multiple_shooting.rs (CasADi's direct_multiple_shooting.py)
  vdp_collocation        examples/src/vdp_collocation.rs (CasADi's direct_collocation.py)
  race_car               examples/src/race_car_ocp.rs (CasADi's race_car.py with the Ocp helper)
  cart_pole              examples/src/cart_pole.rs
  quadrotor              examples/src/quadrotor.rs
  two_link_arm           examples/src/two_link_arm.rs

Prints one JSON line per problem; tests/ocp_examples.rs holds the values.
Usage: python3 benches/reference/ocp_examples.py [name ...]
"""
import json
import sys
from math import inf, pi

from casadi import cos, sin, tan

from ocp_transcription import solve

RK4 = ([[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1, 0]],
       [1 / 6, 1 / 3, 1 / 3, 1 / 6])


def vdp():
    return {
        "nx": 2, "nu": 1,
        "f": lambda x, u: [(1 - x[1] ** 2) * x[0] - x[1] + u[0], x[0]],
        "l": lambda x, u: x[0] ** 2 + x[1] ** 2 + u[0] ** 2,
        "phi": None,
        "x_lb": [-0.25, -inf], "x_ub": [inf, inf], "u_lb": [-1], "u_ub": [1],
        "x0": [0, 1], "xf": None, "horizon": ("fixed", 10.0),
    }


def race_car():
    return {
        "nx": 2, "nu": 1,
        "f": lambda x, u: [x[1], u[0] - x[1]],
        "l": None, "phi": lambda xn, T: T,
        "x_lb": [-inf, -inf], "x_ub": [inf, inf], "u_lb": [0], "u_ub": [1],
        "x0": [0, 0], "xf": None, "horizon": ("free", 0.0, inf, 1.0),
        "path": [lambda x, u: ([x[1] - (1 - sin(2 * pi * x[0]) / 2)], -inf, 0)],
        "boundary": [lambda x0, xn, T: ([xn[0]], 1, 1)],
        "guess_x": lambda t: [0, 1],
    }


CP = dict(m1=1.0, m2=0.3, l=0.5, g=9.81, d=1.0, dmax=2.0, umax=20.0, T=2.0)


def cart_pole():
    m1, m2, l, g = CP["m1"], CP["m2"], CP["l"], CP["g"]

    def f(x, u):
        q2, dq1, dq2 = x[1], x[2], x[3]
        s, c = sin(q2), cos(q2)
        ddq1 = (l * m2 * s * dq2 ** 2 + u[0] + m2 * g * c * s) / (m1 + m2 * (1 - c ** 2))
        ddq2 = -(l * m2 * c * s * dq2 ** 2 + u[0] * c + (m1 + m2) * g * s) / (
            l * m1 + l * m2 * (1 - c ** 2))
        return [dq1, dq2, ddq1, ddq2]

    xf = [CP["d"], pi, 0, 0]
    return {
        "nx": 4, "nu": 1, "f": f, "l": lambda x, u: u[0] ** 2, "phi": None,
        "x_lb": [-CP["dmax"], -inf, -inf, -inf], "x_ub": [CP["dmax"], inf, inf, inf],
        "u_lb": [-CP["umax"]], "u_ub": [CP["umax"]],
        "x0": [0, 0, 0, 0], "xf": xf, "horizon": ("fixed", CP["T"]),
        "guess_x": lambda t: [v * t / CP["T"] for v in xf],
    }


QR = dict(m=0.468, l=0.225, Jx=4.856e-3, Jy=4.856e-3, Jz=8.801e-3, c=0.03826, g=9.81,
          fmax=2.5, T=2.0, tilt=pi / 4)


def quadrotor():
    m, l, Jx, Jy, Jz, c, g = (QR[k] for k in ["m", "l", "Jx", "Jy", "Jz", "c", "g"])
    hover = m * g / 4

    def f(x, u):
        v = x[3:6]
        phi, th, psi = x[6], x[7], x[8]
        wx, wy, wz = x[9], x[10], x[11]
        F = u[0] + u[1] + u[2] + u[3]
        ax = (cos(psi) * sin(th) * cos(phi) + sin(psi) * sin(phi)) * F / m
        ay = (sin(psi) * sin(th) * cos(phi) - cos(psi) * sin(phi)) * F / m
        az = cos(th) * cos(phi) * F / m - g
        dphi = wx + sin(phi) * tan(th) * wy + cos(phi) * tan(th) * wz
        dth = cos(phi) * wy - sin(phi) * wz
        dpsi = (sin(phi) * wy + cos(phi) * wz) / cos(th)
        tx, ty, tz = l * (u[3] - u[1]), l * (u[2] - u[0]), c * (u[0] - u[1] + u[2] - u[3])
        dwx = (tx - (Jz - Jy) * wy * wz) / Jx
        dwy = (ty - (Jx - Jz) * wz * wx) / Jy
        dwz = (tz - (Jy - Jx) * wx * wy) / Jz
        return list(v) + [ax, ay, az, dphi, dth, dpsi, dwx, dwy, dwz]

    xf = [1, 1, 1] + [0] * 9
    tilt = QR["tilt"]
    return {
        "nx": 12, "nu": 4, "f": f,
        "l": lambda x, u: sum((ui - hover) ** 2 for ui in u), "phi": None,
        "x_lb": [-inf] * 6 + [-tilt, -tilt, -inf] + [-inf] * 3,
        "x_ub": [inf] * 6 + [tilt, tilt, inf] + [inf] * 3,
        "u_lb": [0] * 4, "u_ub": [QR["fmax"]] * 4,
        "x0": [0] * 12, "xf": xf, "horizon": ("fixed", QR["T"]),
        "guess_x": lambda t: [v * t / QR["T"] for v in xf],
        "guess_u": lambda t: [hover] * 4,
    }


ARM = dict(m=1.0, l=1.0, lc=0.5, I=1 / 12, tau_max=1.0, q_goal=[pi / 2, -pi / 2], reg=1e-2,
           T_guess=3.0)


def two_link_arm():
    m, l, lc, I = ARM["m"], ARM["l"], ARM["lc"], ARM["I"]

    def f(x, u):
        q2, dq1, dq2 = x[1], x[2], x[3]
        m11 = m * lc ** 2 + I + m * (l ** 2 + lc ** 2 + 2 * l * lc * cos(q2)) + I
        m12 = m * (lc ** 2 + l * lc * cos(q2)) + I
        m22 = m * lc ** 2 + I
        hh = m * l * lc * sin(q2)
        r1 = u[0] + hh * (2 * dq1 * dq2 + dq2 ** 2)
        r2 = u[1] - hh * dq1 ** 2
        det = m11 * m22 - m12 ** 2
        return [dq1, dq2, (m22 * r1 - m12 * r2) / det, (m11 * r2 - m12 * r1) / det]

    xf = ARM["q_goal"] + [0, 0]
    tm = ARM["tau_max"]
    return {
        "nx": 4, "nu": 2, "f": f,
        "l": lambda x, u: ARM["reg"] * (u[0] ** 2 + u[1] ** 2),
        "phi": lambda xn, T: T,
        "x_lb": [-inf] * 4, "x_ub": [inf] * 4, "u_lb": [-tm, -tm], "u_ub": [tm, tm],
        "x0": [0, 0, 0, 0], "xf": xf, "horizon": ("free", 0.1, 10.0, ARM["T_guess"]),
        "guess_x": lambda t: [v * t / ARM["T_guess"] for v in xf],
    }


PROBLEMS = {
    "vdp_multiple_shooting": (vdp, ("ms", RK4[0], RK4[1], 4), 20),
    "vdp_collocation": (vdp, ("colloc", "legendre", 3), 20),
    "race_car": (race_car, ("ms", RK4[0], RK4[1], 1), 100),
    "cart_pole": (cart_pole, ("colloc", "radau", 3), 20),
    "quadrotor": (quadrotor, ("ms", RK4[0], RK4[1], 1), 20),
    "two_link_arm": (two_link_arm, ("colloc", "legendre", 3), 20),
}

if __name__ == "__main__":
    names = sys.argv[1:] or list(PROBLEMS)
    for name in names:
        build, method, n = PROBLEMS[name]
        r = solve(build(), method, n)
        print(json.dumps({"name": name, "N": n, **r}))
