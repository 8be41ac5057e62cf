"""The problem builder, both back ends, options, warm starts, parameters, callbacks,
pickling and errors."""
import pickle
import threading

import numpy as np
import pytest

import symnlp as s
from problems import build_chain, build_hs071


def test_both_back_ends_agree():
    a = s.Problem()
    x = build_hs071(a, s)
    ipm = a.solve()
    sqp = a.solve(solver="sqp")
    assert ipm.success and sqp.success
    # Both stop at tol 1e-8 on the KKT error: objectives agree to ~1e-8 relative.
    assert abs(ipm.objective - sqp.objective) < 1e-7 * ipm.objective
    np.testing.assert_allclose(ipm.value(x), sqp.value(x), atol=1e-6)
    assert len(ipm.lam_g) == a.n_constraints and len(ipm.x) == a.n_variables


def test_same_input_gives_bit_identical_results():
    r = [build_and_solve() for _ in range(2)]
    assert r[0] == r[1]


def build_and_solve():
    pb = s.Problem()
    x = build_hs071(pb, s)
    sol = pb.solve()
    return sol.objective, tuple(sol.value(x)), tuple(sol.lam_g)


def test_native_evaluators_take_the_tape_iterates_bit_for_bit():
    # The JIT computes every value with the tape's operations in the tape's order
    # (symx/tests/jit.rs), so a solve takes the same iterates: equality, no tolerance.
    tape, jit = s.Problem(), s.Problem()
    xt, xj = build_hs071(tape, s), build_hs071(jit, s)
    jit.compile(evaluator="jit")
    a, b = tape.solve(), jit.solve()
    assert a.success and a.iterations == b.iterations
    assert tuple(a.value(xt)) == tuple(b.value(xj)) and tuple(a.lam_g) == tuple(b.lam_g)
    # The choice survives a change that recompiles the problem.
    jit.subject_to(xj[0] <= 4.5)
    tape.subject_to(xt[0] <= 4.5)
    assert tuple(tape.solve().value(xt)) == tuple(jit.solve().value(xj))
    with pytest.raises(s.OptionError, match="unknown evaluator 'llvm'"):
        jit.compile(evaluator="llvm")


def test_options_by_ipopt_names_and_bad_options():
    pb = s.Problem()
    build_hs071(pb, s)
    sol = pb.solve(options={"max_iter": 2})
    assert sol.status == "Maximum_Iterations_Exceeded" and not sol.success
    with pytest.raises(s.OptionError, match="did you mean 'tol'"):
        pb.solve(options={"toll": 1e-8})
    with pytest.raises(s.OptionError, match="unknown solver"):
        pb.solve(solver="snopt")


def test_parameters_change_without_rebuild_and_warm_start():
    pb = s.Problem()
    ys, ends = build_chain(pb, s)
    first = pb.solve()
    assert first.success
    # A lower right end (still within reach: |(1, -0.6)| = 1.17 < 1.25): the chain's energy
    # drops; the update reuses the compiled problem.
    pb.set_value(ends, [0.0, 1.0, 1.0, 0.4])
    cold = pb.solve()
    warm = pb.solve_warm(first)
    assert cold.success and warm.success
    assert cold.objective < first.objective
    # Both converge to tol 1e-8: same optimum to ~1e-8 relative.
    assert abs(warm.objective - cold.objective) < 1e-7 * abs(cold.objective)
    assert warm.value(ys[-1]) == pytest.approx(0.4, abs=1e-9)
    # The same problem built from scratch with the new value: the same solve, bit for bit.
    fresh = s.Problem()
    _, fresh_ends = build_chain(fresh, s)
    fresh.set_value(fresh_ends, [0.0, 1.0, 1.0, 0.4])
    assert fresh.solve().objective == cold.objective


def test_callback_sees_iterations_and_can_stop():
    pb = s.Problem()
    build_hs071(pb, s)
    seen = []

    def cb(info):
        seen.append(info["iter"])
        assert len(info["x"]) == 4
        return info["iter"] < 3  # False at iteration 3 stops

    sol = pb.solve(callback=cb)
    assert sol.status == "User_Requested_Stop" and not sol.success
    assert seen[-1] == 3

    def boom(info):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        pb.solve(callback=boom)


def test_iteration_log():
    pb = s.Problem()
    build_hs071(pb, s)
    sol = pb.solve()
    log = sol.iterations
    assert len(log) == sol.stats["iter_count"] + 1
    assert {"iter", "objective", "inf_pr", "inf_du", "lg_mu", "alpha_pr"} <= set(log[0])
    assert "inf_pr" in sol.log_table()


def test_pickle_round_trips():
    pb = s.Problem()
    x = build_hs071(pb, s)
    sol = pb.solve()
    pb2 = pickle.loads(pickle.dumps(pb))
    sol2 = pb2.solve()
    assert sol2.objective == sol.objective
    assert list(sol2.x) == list(sol.x)
    back = pickle.loads(pickle.dumps(sol))
    assert list(back.value(x)) == list(sol.value(x))
    assert back.stats == sol.stats


def test_pickled_problem_keeps_parameters_cones_and_complementarity():
    pb = s.Problem()
    x = pb.variable("x", 3)
    p = pb.parameter("p")
    pb.set_value(p, 2.0)
    pb.minimize((x[0] - p) ** 2 + (x[1] - 1) ** 2 + x[2])
    pb.subject_to_cone("c", s.vertcat(x[0], x[1]), x[2])
    pb.complementarity("cc", x[0], x[1])
    pb.subject_to(x[0] >= 0, name="nonneg")
    a = pb.solve()
    b = pickle.loads(pickle.dumps(pb)).solve()
    assert a.status == b.status and a.objective == b.objective


def test_solve_in_threads_matches_serial():
    def run(out, k):
        pb = s.Problem()
        build_chain(pb, s, n=30)
        out[k] = pb.solve().objective

    serial = {}
    run(serial, 0)
    par = {}
    ts = [threading.Thread(target=run, args=(par, k)) for k in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert par[0] == par[1] == serial[0]


def test_build_errors_name_what_is_wrong():
    pb = s.Problem()
    pb.variable("x", 2)
    with pytest.raises(s.BuildError, match="x"):
        pb.variable("x", 1)
    y = s.sym("y")
    pb.minimize(y ** 2)  # y is not a variable of pb
    with pytest.raises(s.BuildError):
        pb.solve()
    with pytest.raises(ValueError, match="2 values for 3 entries"):
        q = s.Problem()
        z = q.variable("z", 3)
        q.set_initial(z, [1, 2])
    with pytest.raises(TypeError, match="Constraint"):
        pb.subject_to(3.0)
    with pytest.raises(s.BuildError, match="not an interval"):
        pb.bounded(2, s.sym("w"), 1)


def test_problem_is_bound_to_its_thread():
    pb = s.Problem()
    build_hs071(pb, s)
    err = []

    def other():
        try:
            pb.solve()
        except BaseException as e:  # pyo3 raises on use from another thread
            err.append(e)

    t = threading.Thread(target=other)
    t.start()
    t.join()
    assert err and "another thread" in str(err[0])  # a clear error, not a crash


def test_sensitivity_against_finite_differences():
    def solve_at(y1):
        pb = s.Problem()
        ys, ends = build_chain(pb, s, n=10)
        pb.set_value(ends, [0.0, 1.0, 1.0, y1])
        sol = pb.solve(options={"tol": 1e-12})
        assert sol.success
        return pb, sol

    pb, sol = solve_at(0.5)
    sens = pb.sensitivity(sol)
    dx = sens["dx_dp"]
    assert dx.shape == (pb.n_variables, 4)
    h = 1e-5
    fd = (solve_at(0.5 + h)[1].x - solve_at(0.5 - h)[1].x) / (2 * h)
    # Central differences of solutions converged to 1e-12: error O(h²) + O(1e-12/h)
    # ≈ 1e-7; 1e-5 separates a wrong derivative from that noise.
    np.testing.assert_allclose(dx[:, 3], fd, atol=1e-5)
    assert not sens["weakly_active"]


def test_unpickled_problem_is_rebuilt_in_the_thread_that_uses_it():
    # What Dask distributed does: unpickle on one thread, run the task on another.
    pb = s.Problem()
    build_hs071(pb, s)
    want = pb.solve().objective
    data = pickle.dumps(pb)
    box = {}
    t = threading.Thread(target=lambda: box.update(pb=pickle.loads(data)))
    t.start()
    t.join()
    other = box["pb"]  # unpickled on thread t, used here
    assert other.solve().objective == want
    assert other.n_variables == 4


CLOSED_STDOUT = '''
import symnlp as s
pb = s.Problem()
x = pb.variable("x", 2)
pb.minimize((1 - x[0]) ** 2 + 100 * (x[1] - x[0] ** 2) ** 2)
pb.subject_to(x[0] ** 2 + x[1] ** 2 <= 1.5)
pb.set_initial(x, [-1.2, 1.0])
for solver in ("ipm", "sqp"):
    sol = pb.solve(solver=solver, options={"print_level": 5})
    assert sol.success, solver
    open(OUT + "_" + solver, "w").write(repr(sol.objective))
'''


def test_a_closed_standard_output_does_not_stop_a_logging_solve(tmp_path):
    """The solvers' log (print_level 5) written to a standard output whose reader is
    gone (the program piped into ``head``): the log is dropped, the solves end normally.
    The log used to be printed with Rust's ``println!``, which panics there."""
    import subprocess
    import sys

    out = str(tmp_path / "objective")
    child = subprocess.Popen(
        [sys.executable, "-c", f"OUT = {out!r}\n" + CLOSED_STDOUT],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    child.stdout.close()  # before the first write: every write fails with EPIPE
    _, err = child.communicate(timeout=120)
    assert child.returncode == 0, err.decode()
    for solver in ("ipm", "sqp"):
        # Rosenbrock in the disc x² + y² ≤ 1.5 (README's example): a finite optimum.
        assert float(open(out + "_" + solver).read()) < 1.0


def test_a_nan_bound_is_an_error_naming_the_constraint():
    """``x <= nan`` used to become "no bound" and the solve succeeded without it."""
    pb = s.Problem()
    x = pb.variable("x", 2)
    pb.minimize((x[0] - 1) ** 2 + (x[1] - 2) ** 2)
    with pytest.raises(s.BuildError, match="cap"):
        pb.subject_to(x[0] <= float("nan"), name="cap")
    with pytest.raises(s.BuildError, match="NaN"):
        pb.subject_to(x >= float("nan"))
    # Infinite bounds still mean "no bound" (IPOPT's convention).
    pb.subject_to(x[0] + x[1] <= float("inf"))
    sol = pb.solve()
    assert sol.success
    np.testing.assert_allclose(sol.value(x), [1.0, 2.0], atol=1e-6)
