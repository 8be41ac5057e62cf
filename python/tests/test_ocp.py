"""symnlp.Ocp from Python: every transcription, grids, free horizons, guesses, parameters,
trajectories, the shift, MPC, sensitivities, errors and pickling.

Reference optima: the values the Rust tests check for the identical problems built with
nlp::ocp (docs/ocp.md's doc tests, nlp/tests/ocp_transcriptions.rs), which are IPOPT's on
the identical NLPs (benches/reference/ocp_examples.py, ocp_transcriptions_casadi.py); and,
live, CasADi + IPOPT on the identical transcription (benches/reference/ocp_transcription.py).
"""
import math
import pathlib
import pickle
import sys
import threading

import numpy as np
import pytest

import symnlp as s

INF = math.inf
REFERENCE = pathlib.Path(__file__).resolve().parents[2] / "benches" / "reference"


def close(got, want, rel):
    assert abs(got - want) <= rel * abs(want), f"{got} vs {want} (rel {abs(got - want) / abs(want):.2e})"


# Module-level callables: picklable by plain pickle (a lambda needs cloudpickle).
def vdp_dynamics(x, u, p):
    return [(1 - x[1] ** 2) * x[0] - x[1] + u[0], x[0]]


def vdp_cost(x, u, p):
    return x[0] ** 2 + x[1] ** 2 + u[0] ** 2


def vdp_lower_bound(x, u, p):
    return x[0] >= -0.25


def van_der_pol():
    """CasADi's direct_multiple_shooting.py / direct_collocation.py problem (docs/ocp.md §1)."""
    ocp = s.Ocp(["x1", "x2"], ["u"])
    ocp.set_dynamics(vdp_dynamics)
    ocp.set_stage_cost(vdp_cost)
    ocp.set_horizon(10.0)
    ocp.set_initial_state([0.0, 1.0])
    ocp.set_state_bounds([-0.25, None], None)
    ocp.set_control_bounds([-1.0], [1.0])
    return ocp


def test_van_der_pol_multiple_shooting_and_collocation():
    ocp = van_der_pol()
    tr = ocp.transcribe(s.Method.multiple_shooting("rk4", 4), 20)
    sol = tr.solve()
    traj = tr.trajectory(sol)
    assert traj.success, traj.status
    # docs/ocp.md's doc test: IPOPT's optimum on the identical NLP; the Rust test allows
    # 1e-6 at the default tol 1e-8.
    assert abs(traj.objective - 3.732969410715394) < 1e-6
    assert traj.time.shape == (21,) and traj.states.shape == (2, 21)
    assert traj.controls.shape == (1, 20) and traj.control_time.shape == (20,)
    assert np.all(traj.state("x1") >= -0.25 - 1e-8)
    assert np.array_equal(traj.states[0], traj.state("x1"))
    assert np.array_equal(sol.value(tr.states)[1], traj.state("x2"))

    tr = ocp.transcribe(s.Method.collocation("legendre", 3), 20)
    sol = tr.solve(solver="sqp")
    traj = tr.trajectory(sol)
    assert traj.success, traj.status
    assert abs(traj.objective - 3.7774566843106947) < 1e-6
    assert traj.collocation_states.shape == (2, 60)
    assert traj.collocation_time.shape == (60,)


def casadi_reference():
    pytest.importorskip("casadi")
    sys.path.insert(0, str(REFERENCE))
    try:
        import ocp_examples
    finally:
        sys.path.pop(0)
    return ocp_examples


@pytest.mark.parametrize("name,method", [
    ("vdp_multiple_shooting", s.Method.multiple_shooting("rk4", 4)),
    ("vdp_collocation", s.Method.collocation("legendre", 3)),
])
def test_same_optimum_as_casadi_ipopt_on_the_identical_transcription(name, method):
    ref = casadi_reference()
    build, ref_method, n = ref.PROBLEMS[name]
    want = ref.solve(build(), ref_method, n, {"tol": 1e-10})
    assert want["status"] == "Solve_Succeeded"
    tr = van_der_pol().transcribe(method, n)
    got = tr.solve(options={"tol": 1e-10})
    assert got.success, got.status
    # Both stop at tol 1e-10 on the identical NLP: the optima agree to ~1e-10 relative
    # (the Rust test of the same pair, tests/ocp_examples.rs, allows 1e-7).
    close(got.objective, want["objective"], 1e-8)


def test_calls_give_the_same_problem_as_inlined():
    ocp = van_der_pol()
    a = ocp.transcribe(s.Method.multiple_shooting("rk4", 4), 20).solve()
    b = ocp.transcribe(s.Method.multiple_shooting("rk4", 4, calls=True), 20).solve()
    # docs/ocp.md §3: the same NLP, the same iterates to rounding.
    assert a.stats["iter_count"] == b.stats["iter_count"]
    close(b.objective, a.objective, 1e-12)


def test_dynamics_as_a_compiled_function():
    x, u, p = s.sym("x", 2), s.sym("u", 1), s.sym("p", 0)
    f = s.Function("vdp", [x, u, p], [s.vertcat(*vdp_dynamics(x, u, p))])
    ocp = van_der_pol()
    ocp.set_dynamics_function(f)
    sol = ocp.transcribe(s.Method.multiple_shooting("rk4", 4, calls=True), 20).solve()
    assert abs(sol.objective - 3.732969410715394) < 1e-6


def goddard():
    """COPS 3.0 problem 10 as nlp/tests/ocp_transcriptions.rs writes it."""
    h0, m0, g0, hc, vc = 1.0, 1.0, 1.0, 500.0, 620.0
    c = 0.5 * math.sqrt(g0 * h0)
    mf, dc, tmax = 0.6 * m0, 0.5 * vc * m0 / g0, 3.5 * g0 * m0
    ocp = s.Ocp(["h", "v", "m"], ["T"])

    def f(x, u, p):
        drag = dc * x[1] ** 2 * s.exp(-hc * (x[0] - h0) / h0)
        gravity = g0 * (h0 / x[0]) ** 2
        return [x[1], (u[0] - drag) / x[2] - gravity, -u[0] / c]

    ocp.set_dynamics(f)
    ocp.set_terminal_cost(lambda xT, p, T: -xT[0])
    ocp.set_free_horizon(0.0, INF, 1.0)
    ocp.set_initial_state([h0, 0.0, m0])
    ocp.add_boundary_constraint("final mass", lambda x0, xT, p, T: xT[2] == mf)
    ocp.set_state_bounds([h0, 0.0, mf], [None, None, m0])
    ocp.set_control_bounds([0.0], [tmax])
    ocp.set_control_interpolation("linear")
    ocp.set_state_guess(lambda t: [1.0, t * (1.0 - t), (mf - m0) * t + m0])
    ocp.set_control_guess(lambda t: [tmax / 2.0])
    return ocp


def test_goddard_rocket_trapezoidal_free_final_time():
    tr = goddard().transcribe(s.Method.trapezoidal(), 100)
    sol = tr.solve(options={"tol": 1e-10})
    t = tr.trajectory(sol)
    assert t.success, t.status
    # ocp_transcriptions_casadi.py: h(T) = 1.012832023909441, T = 0.1987691459257406
    # (COPS 3.0 reports 1.01283); tolerances as the Rust test's.
    close(-t.objective, 1.012832023909441, 1e-9)
    close(t.final_time, 0.1987691459257406, 1e-8)
    close(sol.value(tr.final_time), 0.1987691459257406, 1e-8)
    assert t.controls.shape == (1, 101) and t.control_interpolation == "linear"
    close(t.state("h")[100], 1.012832023909441, 1e-9)


def bryson_denham():
    ocp = s.Ocp(["x", "v"], ["u"])
    ocp.set_dynamics(lambda x, u, p: s.vertcat(x[1], u[0]))
    ocp.set_stage_cost(lambda x, u, p: 0.5 * u[0] ** 2)
    ocp.set_horizon(1.0)
    ocp.set_initial_state([0.0, 1.0])
    ocp.set_final_state([0.0, -1.0])
    ocp.set_state_bounds([None, None], [1.0 / 9.0, None])
    ocp.set_control_interpolation("linear")
    return ocp


@pytest.mark.parametrize("method,ipopt", [
    (s.Method.trapezoidal(), 4.038475872103792),
    (s.Method.hermite_simpson(), 3.999999640224972),
    (s.Method.hermite_simpson(separated=True), 3.9999996404934524),
])
def test_bryson_denham_by_each_method(method, ipopt):
    # ocp_transcriptions_casadi.py, N = 30, tol 1e-10; the Rust test allows 1e-9.
    sol = bryson_denham().transcribe(method, s.Grid.uniform(30)).solve(options={"tol": 1e-10})
    assert sol.success, sol.status
    close(sol.objective, ipopt, 1e-9)


def test_user_given_grid_and_the_shift_needs_a_uniform_one():
    fr = [0.25 * k / 10 for k in range(10)] + [0.25 + 0.75 * k / 20 for k in range(21)]
    tr = bryson_denham().transcribe(s.Method.hermite_simpson(), s.Grid(fr))
    sol = tr.solve(options={"tol": 1e-10})
    t = tr.trajectory(sol)
    close(t.objective, 3.9997756677774317, 1e-9)  # ocp_transcriptions_casadi.py
    assert t.time[10] == 0.25
    with pytest.raises(s.BuildError, match="uniform grid"):
        tr.shift(sol)


def test_guess_from_a_coarser_solution():
    ocp = van_der_pol()
    coarse = ocp.transcribe(s.Method.trapezoidal(), 10)
    t = coarse.trajectory(coarse.solve())
    ocp.set_guess_from(t)
    fine = ocp.transcribe(s.Method.trapezoidal(), 40)
    # The starting point (a callback returning False stops at iteration 0): every 4th
    # node of the fine grid is a coarse node; it starts there, up to IPOPT's bound_push
    # (1e-2) that moves the guesses lying on the bound x1 >= -0.25 inside.
    start = fine.trajectory(fine.solve(callback=lambda info: False))
    assert np.abs(start.states[:, ::4] - t.states).max() <= 1e-2 + 1e-12
    assert np.array_equal(start.controls[:, ::4], t.controls)
    sol = fine.solve()
    cold = van_der_pol().transcribe(s.Method.trapezoidal(), 40).solve()
    assert sol.success and cold.success
    close(sol.objective, cold.objective, 1e-7)  # the same optimum from another start


def lq_with_parameter():
    ocp = s.Ocp(["x"], ["u"])
    ocp.add_parameter("x0", [1.0])
    ocp.set_dynamics(lambda x, u, p: -x[0] + u[0])
    ocp.set_stage_cost(lambda x, u, p: x[0] ** 2 + u[0] ** 2)
    ocp.set_horizon(1.0)
    ocp.add_boundary_constraint("start", lambda x0, xT, p, T: x0[0] == p[0])
    return ocp


def test_parameters_and_sensitivities():
    tr = lq_with_parameter().transcribe(s.Method.multiple_shooting("rk4", 2), 10)
    sol = tr.solve()
    sens = tr.sensitivity(sol)
    # docs/ocp.md §6: linear-quadratic, so x* is linear in x(0): x* = x(0)·dx*/dx(0).
    assert np.allclose(sol.x, sens["dx_dp"][:, 0], atol=1e-6)
    tr.set_value("x0", [2.0])  # no rebuild
    sol2 = tr.solve()
    assert np.allclose(sol2.x, 2 * sol.x, atol=1e-6)
    close(sol2.objective, 4 * sol.objective, 1e-8)


def regulator():
    """docs/mpc.md §1: stabilise ẋ = x + u at 0 with |u| ≤ 2."""
    ocp = s.Ocp(["x"], ["u"])
    ocp.set_dynamics(lambda x, u, p: x[0] + u[0])
    ocp.set_stage_cost(lambda x, u, p: x[0] ** 2 + 0.1 * u[0] ** 2)
    ocp.set_horizon(1.0)
    ocp.set_control_bounds([-2.0], [2.0])
    ocp.set_initial_state_parameter("x0", [1.0])
    return ocp


def test_a_transcription_compiled_to_native_code_takes_the_tapes_iterates():
    # The JIT computes every value as the tape does (symx/tests/jit.rs): the same
    # iterates bit for bit, so equality without a tolerance.
    method = s.Method.multiple_shooting("rk4", 4)
    tape, jit = van_der_pol().transcribe(method, 20), van_der_pol().transcribe(method, 20)
    jit.compile(evaluator="jit")
    a, b = tape.solve(), jit.solve()
    assert a.iterations == b.iterations and a.objective == b.objective
    assert np.array_equal(a.value(tape.states), b.value(jit.states))
    with pytest.raises(s.OptionError, match="unknown evaluator"):
        tape.compile(evaluator="gcc")


def test_mpc_closed_loop_with_the_simulator_and_a_python_plant():
    ocp = regulator()
    tr = ocp.transcribe(s.Method.multiple_shooting("rk4", 1), 10)
    mpc = s.Mpc(tr)
    assert mpc.sampling_period == pytest.approx(0.1)
    run = mpc.run([1.5], 30, ocp.simulator("rk4", 1))
    assert run["all_succeeded"]
    assert run["states"].shape == (31, 1) and run["controls"].shape == (30, 1)
    assert abs(run["states"][30][0]) < 1e-3  # the Rust doc test's goal
    assert [r["warm"] for r in run["steps"][:2]] == [False, True]

    # The same loop with the plant as a Python callable (explicit RK4 of the same model)
    # gives the same closed loop (both integrate the identical model, rounding aside).
    def plant(x, u):
        f = lambda z: z + u[0]
        h = 0.1
        k1 = f(x[0]); k2 = f(x[0] + h / 2 * k1); k3 = f(x[0] + h / 2 * k2); k4 = f(x[0] + h * k3)
        return [x[0] + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)]

    again = s.Mpc(tr).run([1.5], 30, plant)
    assert np.allclose(again["states"], run["states"], rtol=0, atol=1e-12)


def test_mpc_step_by_step_equals_shift_and_warm_solves():
    ocp = regulator()
    tr = ocp.transcribe(s.Method.multiple_shooting("rk4", 1), 10)
    mpc = s.Mpc(tr)
    x = [1.0]
    tr.set_value("x0", x)
    prev = tr.solve()
    first = mpc.step(x)
    assert first["success"] and not first["warm"]
    assert first["residual"] is None  # only a real-time iteration reports one
    assert mpc.control[0] == pytest.approx(prev.value(tr.controls[0, 0]), abs=1e-12)
    # The next step: Mpc shifts and warm-starts; by hand: shift, set x0, solve_warm.
    x = [x[0] + 0.1 * (x[0] + mpc.control[0])]
    second = mpc.step(x)
    tr.set_value("x0", x)
    by_hand = tr.solve_warm(tr.shift(prev))
    assert second["warm"] and by_hand.success
    assert mpc.solution.objective == pytest.approx(by_hand.objective, rel=1e-8)
    with pytest.raises(s.SolveError, match="measured state"):
        mpc.step([1.0, 2.0])


def test_mpc_by_real_time_iterations_and_native_evaluators():
    ocp = regulator()
    tr = ocp.transcribe(s.Method.multiple_shooting("rk4", 1), 10)
    plant = ocp.simulator("rk4", 1)
    ipm = s.Mpc(tr).run([1.5], 20, plant)
    # The transcription is a strictly convex QP (linear dynamics, quadratic cost), where
    # one real-time iteration is the QP's solution: the RTI loop is the converged loop
    # to the interior point's tolerance (tol 1e-8 on the KKT error; 1e-6 on states).
    rti = s.Mpc(tr, solver="rti").run([1.5], 20, plant)
    assert rti["all_succeeded"]
    assert [r["status"] for r in rti["steps"][1:]] == ["Real_Time_Iteration_Taken"] * 19
    assert np.allclose(rti["states"], ipm["states"], rtol=0, atol=1e-6)
    # Step by step with the preparation run ahead: the step is the feedback alone.
    mpc = s.Mpc(tr, solver="rti", options={"print_level": 0})
    x = [1.5]
    mpc.step(x)
    x = plant.step(x, mpc.control, mpc.sampling_period)
    assert mpc.prepare() > 0.0 and mpc.prepare() == 0.0  # the second finds it prepared
    r = mpc.step(x)
    assert r["status"] == "Real_Time_Iteration_Taken"
    # The step's seconds count the preparation that ran ahead; the feedback is a part.
    assert 0.0 < r["feedback_seconds"] < r["solve_seconds"] <= r["seconds"]
    # Native evaluators: the same iterates bit for bit, so the same loop exactly.
    for solver in ["ipm", "rti"]:
        tape = s.Mpc(tr, solver=solver).run([1.5], 20, plant)
        jit = s.Mpc(tr, solver=solver, evaluator="jit").run([1.5], 20, plant)
        assert np.array_equal(tape["states"], jit["states"]), solver
    with pytest.raises(s.OptionError, match="unknown evaluator"):
        s.Mpc(tr, evaluator="fast")
    with pytest.raises(s.OptionError, match="toll"):
        s.Mpc(tr, solver="rti", options={"toll": 1e-8})
    with pytest.raises(s.OptionError, match="expected 'ipm', 'sqp' or 'rti'"):
        s.Mpc(tr, solver="acados")


def test_mpc_refuses_a_fixed_initial_state():
    with pytest.raises(s.BuildError, match="set_initial_state_parameter"):
        s.Mpc(van_der_pol().transcribe(s.Method.trapezoidal(), 10))


def test_errors_name_what_is_wrong():
    ocp = s.Ocp(["x", "v"], ["u"])
    with pytest.raises(s.BuildError, match="state bounds"):
        ocp.set_state_bounds([0.0], [1.0])
    with pytest.raises(s.BuildError, match="horizon"):
        ocp.set_horizon(-1.0)
    with pytest.raises(s.BuildError, match="set_horizon"):
        ocp.set_dynamics(lambda x, u, p: [x[1], u[0]])
        ocp.transcribe(s.Method.trapezoidal(), 10)
    ocp.set_horizon(1.0)
    ocp.set_dynamics(lambda x, u, p: [x[1]])  # one entry for two states
    with pytest.raises(s.BuildError, match="dynamics output"):
        ocp.transcribe(s.Method.trapezoidal(), 10)

    def broken(x, u, p):
        raise ZeroDivisionError("model bug")

    ocp.set_dynamics(broken)
    with pytest.raises(s.BuildError, match="Ocp dynamics: .*model bug") as info:
        ocp.transcribe(s.Method.multiple_shooting(), 10)
    assert isinstance(info.value.__cause__, ZeroDivisionError)
    ocp.set_dynamics(lambda x, u, p: [x[1], u[0]])
    ocp.add_path_constraint("bad", lambda x, u, p: x[0] + 1)  # not a constraint
    with pytest.raises(s.BuildError, match="path constraint 'bad'"):
        ocp.transcribe(s.Method.trapezoidal(), 10)
    ok = s.Ocp(["x"], ["u"])
    ok.set_initial_state([0.0])
    with pytest.raises(s.BuildError, match="initial state"):
        ok.set_initial_state_parameter("x0", [0.0])
    with pytest.raises(ValueError, match="radau"):
        s.Method.collocation("gauss", 3)
    with pytest.raises(s.BuildError, match="degree"):
        s.Method.collocation("radau", 0)
    with pytest.raises(s.BuildError, match="increasing"):
        s.Grid([0.0, 0.6, 0.5, 1.0])
    with pytest.raises(s.BuildError, match="explicit"):
        s.ButcherTableau("implicit", [[1.0]], [1.0], [1.0])
    with pytest.raises(TypeError, match="number N"):
        van_der_pol().transcribe(s.Method.trapezoidal(), "ten")


def test_custom_tableau_equals_the_builtin():
    rk4 = s.ButcherTableau(
        "my rk4",
        [[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1, 0]],
        [1 / 6, 1 / 3, 1 / 3, 1 / 6],
        [0, 0.5, 0.5, 1],
    )
    a = van_der_pol().transcribe(s.Method.multiple_shooting(rk4, 4), 20).solve()
    b = van_der_pol().transcribe(s.Method.multiple_shooting("rk4", 4), 20).solve()
    assert a.objective == b.objective and np.array_equal(a.x, b.x)


def test_pickling_ocp_transcription_trajectory():
    ocp = van_der_pol()
    tr = ocp.transcribe(s.Method.multiple_shooting("rk4", 4), 20)
    sol = tr.solve()
    t = tr.trajectory(sol)
    t2 = pickle.loads(pickle.dumps(t))
    assert np.array_equal(t2.states, t.states) and t2.status == t.status
    assert s.Trajectory.from_json(t.to_json()).to_dict() == t.to_dict()

    ocp2 = pickle.loads(pickle.dumps(ocp))
    again = ocp2.transcribe(s.Method.multiple_shooting("rk4", 4), 20).solve()
    assert np.array_equal(again.x, sol.x)  # bit-identical

    # A transcription unpickles lazily and is written by the thread that uses it (as
    # Dask does: unpickle on one thread, run on another).
    blob = pickle.dumps(tr)
    out = {}

    def worker():
        tr2 = pickle.loads(blob)
        out["sol"] = tr2.solve()
        out["traj"] = tr2.trajectory(out["sol"])

    th = threading.Thread(target=worker)
    th.start()
    th.join()
    assert np.array_equal(out["sol"].x, sol.x)
    assert np.array_equal(out["traj"].states, t.states)
    holder = {}

    def use():
        mine = pickle.loads(blob)
        mine.compile()  # written in this worker's graph
        holder["tr"] = mine

    th = threading.Thread(target=use)
    th.start()
    th.join()
    with pytest.raises(s.BuildError, match="another thread"):
        holder["tr"].solve()


def test_lambdas_pickle_with_cloudpickle_not_pickle():
    ocp = bryson_denham()  # lambdas
    with pytest.raises((pickle.PicklingError, AttributeError)):
        pickle.dumps(ocp)
    cloudpickle = pytest.importorskip("cloudpickle")
    ocp2 = cloudpickle.loads(cloudpickle.dumps(ocp))
    a = ocp.transcribe(s.Method.trapezoidal(), 30).solve()
    b = ocp2.transcribe(s.Method.trapezoidal(), 30).solve()
    assert np.array_equal(a.x, b.x)


def test_parameters_survive_pickling_of_a_transcription():
    tr = lq_with_parameter().transcribe(s.Method.multiple_shooting("rk4", 2), 10)
    tr.set_value("x0", [3.0])
    sol = tr.solve()
    cloudpickle = pytest.importorskip("cloudpickle")  # the model is lambdas
    tr2 = cloudpickle.loads(cloudpickle.dumps(tr))
    assert np.array_equal(tr2.solve().x, sol.x)
