"""Reference values and timings of CasADi's CVODES for nlp::integrator (issue 22).

Prints JSON: for each problem, x(T) and the Jacobian dx(T)/d(x0, p) (column-major) from
CVODES at tight tolerances (rtol 1e-12, atol 1e-14: the reference values used by
nlp/tests/integrator.rs), and the median wall time of one integration at the comparison
tolerances (rtol 1e-6, atol 1e-8) over interleaved repetitions. Also the Jacobian from
CVODES at the comparison tolerances with the sensitivities in the error control
(`fsens_err_con` true) and without (false): the values nlp/tests/integrator_sens_error.rs
compares with.

Usage: python3 benches/reference/integrator_casadi.py
"""
import json
import time

import casadi as ca
import numpy as np


def problems():
    x = ca.SX.sym("x", 2)
    mu = ca.SX.sym("mu")
    vdp = ca.vertcat(x[1], mu * (1 - x[0] ** 2) * x[1] - x[0])
    y = ca.SX.sym("y", 3)
    k = ca.SX.sym("k", 3)
    rob = ca.vertcat(
        -k[0] * y[0] + k[1] * y[1] * y[2],
        k[0] * y[0] - k[1] * y[1] * y[2] - k[2] * y[1] ** 2,
        k[2] * y[1] ** 2,
    )
    return {
        # non-stiff: Van der Pol, mu = 1, x0 = (2, 0), T = 5
        "vdp1": (x, mu, vdp, [2.0, 0.0], [1.0], 5.0),
        # stiff: Van der Pol, mu = 1000, T = 1000 (one slow phase)
        "vdp1000": (x, mu, vdp, [2.0, 0.0], [1000.0], 1000.0),
        # stiff: Robertson, T = 40 (Hairer & Wanner's test set)
        "robertson": (y, k, rob, [1.0, 0.0, 0.0], [0.04, 1e4, 3e7], 40.0),
        # stiff: Robertson to T = 4e10 (the long-time test of Hairer & Wanner's test set)
        "robertson4e10": (y, k, rob, [1.0, 0.0, 0.0], [0.04, 1e4, 3e7], 4e10),
        # stiff: Van der Pol, mu = 1000, T = 2000: more than one period ((3 - 2 ln 2) mu ~ 1614)
        "vdp1000_2000": (x, mu, vdp, [2.0, 0.0], [1000.0], 2000.0),
    }


def main():
    out = {}
    for name, (x, p, rhs, x0, p0, T) in problems().items():
        dae = {"x": x, "p": p, "ode": rhs}
        ref = ca.integrator("ref", "cvodes", dae, 0.0, T, {"abstol": 1e-14, "reltol": 1e-12, "max_num_steps": 10**7})
        res = ref(x0=x0, p=p0)
        jac = ref.factory("sens", ["x0", "p"], ["xf", "jac:xf:x0", "jac:xf:p"])
        xf, jx, jp = jac(x0, p0)
        J = np.hstack([np.array(jx), np.array(jp)])
        cmp = ca.integrator("cmp", "cvodes", dae, 0.0, T, {"abstol": 1e-8, "reltol": 1e-6, "max_num_steps": 10**7})
        loose = {}
        for con in (True, False):
            opts = {"abstol": 1e-8, "reltol": 1e-6, "max_num_steps": 10**7, "fsens_err_con": con}
            sens = ca.integrator("loose", "cvodes", dae, 0.0, T, opts).factory(
                "sens", ["x0", "p"], ["jac:xf:x0", "jac:xf:p"]
            )
            lx, lp = sens(x0, p0)
            loose[con] = np.hstack([np.array(lx), np.array(lp)]).ravel(order="F").tolist()
        times = []
        for _ in range(15):
            t = time.perf_counter()
            r = cmp(x0=x0, p=p0)
            times.append(time.perf_counter() - t)
        stats = cmp.stats()
        out[name] = {
            "T": T,
            "x0": x0,
            "p": p0,
            "xf_ref": np.array(res["xf"]).ravel().tolist(),
            "jac_ref_colmajor": J.ravel(order="F").tolist(),
            "xf_rtol1e-6": np.array(r["xf"]).ravel().tolist(),
            "cvodes_rtol1e-6_median_s": float(np.median(times)),
            "cvodes_rtol1e-6_steps": int(stats.get("nsteps", -1)),
            "jac_rtol1e-6_fsens_err_con": loose[True],
            "jac_rtol1e-6_no_fsens_err_con": loose[False],
        }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
