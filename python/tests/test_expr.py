"""Expressions, derivatives against central finite differences, Functions, sparsity."""
import math

import numpy as np
import pytest

import symnlp as s


def fd_jacobian(fun, x, h=1e-6):
    x = np.asarray(x, dtype=float)
    f0 = np.atleast_1d(fun(x))
    J = np.zeros((f0.size, x.size))
    for j in range(x.size):
        e = np.zeros_like(x)
        e[j] = h
        J[:, j] = (np.atleast_1d(fun(x + e)) - np.atleast_1d(fun(x - e))) / (2 * h)
    return J


def test_operators_and_printing():
    x = s.sym("x")
    y = s.sym("y")
    e = 2 * x + y / 3 - x ** 2
    assert "x" in str(e) and "y" in str(e)
    f = s.Function("f", [s.vertcat(x, y)], [e])
    assert f([1.5, 3.0]) == pytest.approx(2 * 1.5 + 1.0 - 1.5 ** 2, rel=0, abs=1e-15)
    v = s.sym("v", 3)
    assert v.shape == (3, 1) and len(v) == 3
    assert v[1:].shape == (2, 1)
    assert v[-1].name() == "v[2]"
    M = s.sym("M", 2, 2)
    assert M.shape == (2, 2) and M.T.shape == (2, 2)


def test_numpy_interop():
    x = s.sym("x", 2)
    A = np.array([[1.0, 2.0], [3.0, 4.0]])
    b = np.array([1.0, -1.0])
    e = A @ x + b  # numpy defers to Expr
    f = s.Function("f", [x], [e, np.float64(2.0) * x])
    y, z = f(np.array([0.5, 0.25]))
    np.testing.assert_array_equal(y, A @ [0.5, 0.25] + b)
    np.testing.assert_array_equal(z, [1.0, 0.5])


def test_jacobian_gradient_hessian_against_finite_differences():
    x = s.sym("x", 3)
    f = s.sin(x[0]) * s.exp(x[1]) + x[0] ** 3 * x[2] + s.sqrt(1 + x[1] ** 2) * s.atan2(x[2], 2.0)
    g = s.vertcat(f, x[0] * x[1], s.tanh(x[2]) + s.log(2 + x[0]))
    J = s.Function("J", [x], [s.jacobian(g, x)])
    G = s.Function("G", [x], [s.gradient(f, x)])
    H = s.Function("H", [x], [s.hessian(f, x)])
    F = s.Function("F", [x], [g])
    fs = s.Function("fs", [x], [f])
    x0 = np.array([0.3, -0.7, 1.1])
    # Central differences with h = 1e-6 have truncation error O(h²)·f''' and rounding
    # error O(eps/h) ~ 1e-10: 1e-7 separates a wrong derivative from noise.
    np.testing.assert_allclose(J(x0), fd_jacobian(F, x0), atol=1e-7)
    np.testing.assert_allclose(G(x0), fd_jacobian(fs, x0)[0], atol=1e-7)
    np.testing.assert_allclose(H(x0), fd_jacobian(G, x0), atol=1e-7)


def test_a_jit_function_gives_the_tapes_bits():
    # The JIT runs the tape's operations in the tape's order (symx/tests/jit.rs): equal
    # bits, NaN and infinities included, no tolerance.
    x = s.sym("x", 3)
    f = s.sin(x[0]) * s.exp(x[1]) + x[0] ** 3 * x[2] + s.sqrt(1 + x[1] ** 2) * s.atan2(x[2], 2.0)
    outs = [s.vertcat(f, x[0] / x[1], s.log(x[2])), s.hessian(f, x)]
    tape = s.Function("t", [x], outs)
    jit = s.Function("t", [x], outs, evaluator="jit")
    for x0 in ([0.3, -0.7, 1.1], [0.0, 0.0, -1.0], [math.inf, 1.0, 0.0], [math.nan, 2.0, 3.0]):
        for a, b in zip(tape(x0), jit(x0)):
            assert np.asarray(a).tobytes() == np.asarray(b).tobytes(), x0
    with pytest.raises(s.OptionError, match="unknown evaluator"):
        s.Function("t", [x], outs, evaluator="gcc")


def test_if_else_and_comparisons():
    x = s.sym("x")
    e = s.if_else(s.gt(x, 0), x ** 2, -x)
    f = s.Function("f", [x], [e])
    assert f(2.0) == 4.0 and f(-3.0) == 3.0


def test_jacobian_sparsity_is_scipy_csc():
    sp = pytest.importorskip("scipy.sparse")
    x = s.sym("x", 3)
    g = s.vertcat(x[0] * x[1], x[2] ** 2)
    indptr, indices, shape = s.jacobian_sparsity(g, x)
    m = sp.csc_matrix((np.ones(len(indices)), indices, indptr), shape=shape)
    np.testing.assert_array_equal(m.toarray() != 0, [[1, 1, 0], [0, 0, 1]])
    f = s.Function("f", [x], [g])
    indptr, indices, shape = f.sparsity(0, 0)
    assert shape == (2, 3) and list(indptr) == [0, 1, 2, 3]


def test_matrix_outputs_are_2d_column_major():
    M = s.sym("M", 2, 3)
    f = s.Function("f", [M], [2 * M])
    vals = np.arange(6.0).reshape(2, 3)
    np.testing.assert_array_equal(f(vals), 2 * vals)


def test_errors_are_exceptions_with_messages():
    x = s.sym("x", 2)
    with pytest.raises(ValueError, match="shapes"):
        x + s.sym("y", 3)
    with pytest.raises(ValueError, match="not a symbol"):
        s.jacobian(x[0] ** 2, x * 2)
    f = s.Function("f", [x], [x[0]])
    with pytest.raises(s.BuildError):
        f([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="expected 1 inputs"):
        f([1.0, 2.0], [3.0])
    with pytest.raises(TypeError):
        bool(x[0] >= 0)
    assert math.isfinite(f([1.0, 2.0]))


def test_a_bare_expr_pickles_by_its_printed_form():
    import pickle

    pb = s.Problem()
    x = pb.variable("x", 2)
    e = s.vertcat(s.sin(x[0]) * x[1] ** 2, s.if_else(s.gt(x[0], 0), x[0], -x[1]))
    pb.minimize((x[0] - 1) ** 2 + (x[1] - 2) ** 2)
    sol = pb.solve()
    e2 = pickle.loads(pickle.dumps(e))
    assert e2.shape == e.shape and str(e2) == str(e)
    # New symbols of the same names: a Solution finds them by name.
    assert np.array_equal(sol.value(e2), sol.value(e))
    m = s.Expr(np.arange(6.0).reshape(2, 3))
    assert np.array_equal(pickle.loads(pickle.dumps(m)).to_numpy(), m.to_numpy())


def test_what_cannot_pickle_says_why():
    import pickle

    twins = s.sym("x") + s.sym("x")  # two symbols, one name
    with pytest.raises(TypeError, match="two different symbols are named 'x'"):
        pickle.dumps(twins)
    with pytest.raises(TypeError, match="'my var' does not parse back"):
        pickle.dumps(s.sym("my var") * 2)
    x = s.sym("x", 2)
    f = s.Function("f", [x], [x * 2])
    with pytest.raises(TypeError, match="cannot pickle Function 'f'"):
        pickle.dumps(f)
