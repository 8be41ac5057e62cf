"""Same optimum as CasADi + IPOPT (3.8.2) on every problem of problems.py, each built once
from one formulation in both tools; and as the published optimum where there is one."""
import pytest

import symnlp
from problems import PROBLEMS, PUBLISHED, CasadiOpti

casadi = pytest.importorskip("casadi")


# Found by this suite: the SQP back end reports Solve_Succeeded on the (convex) 20-link
# chain at f = 12.2632967, 1.3e-6 above the optimum 12.2632810 that IPOPT and the IPM
# reach (feasible to 5e-14, so the stop is on a dual measure). Reported, not hidden: the
# mark is strict, so the test fails once the SQP is fixed and the mark must go.
SQP_CHAIN = pytest.mark.xfail(strict=True, reason="SQP stops early on chain20 (see comment)")

CASES = [
    pytest.param(name, solver, marks=SQP_CHAIN if (name, solver) == ("chain20", "sqp") else ())
    for name in sorted(PROBLEMS)
    for solver in ["ipm", "sqp"]
]


@pytest.mark.parametrize("name,solver", CASES)
def test_same_optimum_as_casadi_ipopt(name, solver):
    build = PROBLEMS[name]
    pb = symnlp.Problem()
    build(pb, symnlp)
    sol = pb.solve(solver=solver, options={"tol": 1e-10})
    assert sol.success, sol.status

    ref = CasadiOpti()
    build(ref, casadi)
    f_ref, _ = ref.solve()

    # Both solvers stop at tol 1e-10 on the scaled KKT error; the objectives then agree
    # to ~1e-8 relative (absolute near a zero optimum).
    assert abs(sol.objective - f_ref) <= 1e-7 * max(1.0, abs(f_ref))
    if name in PUBLISHED:
        assert abs(sol.objective - PUBLISHED[name]) <= 1e-6 * max(1.0, abs(PUBLISHED[name]))
