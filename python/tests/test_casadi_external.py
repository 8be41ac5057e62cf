"""symx's generated C (`Function::to_c`) loaded by CasADi's `external()`.

`cargo run --release -p symnlp-examples --example casadi_external` writes the C files of a small function (with
a sparse Jacobian output) and of the gap-crossing model's objective gradient, together with
symx's own outputs at a test point (`examples/examples/casadi_external.rs`). Each file is compiled by
the system's C compiler into a shared library, loaded with `casadi.external`, and evaluated
by CasADi: the interface (names, sizes, sparsity) is the symx function's and the values are
symx's bit for bit (the C performs the tape's IEEE operations in the tape's order and calls
the same C library functions; `-std=c99` keeps the compiler from contracting into FMAs).
The small function is also built in CasADi's SX and compared (values computed elsewhere).
"""
import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

casadi = pytest.importorskip("casadi")

ROOT = Path(__file__).resolve().parents[2]


def c_compiler():
    """The C compiler: $CC, else `cc` on the PATH, else None."""
    cc = os.environ.get("CC", "cc")
    return shutil.which(cc)


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """Directory holding `<name>.c` and `<name>.json` of every example function."""
    if c_compiler() is None:
        pytest.skip("no C compiler ($CC or cc) to compile the generated C")
    out = tmp_path_factory.mktemp("casadi_external")
    cargo = os.environ.get("CARGO", "cargo")
    subprocess.run(
        [cargo, "run", "--release", "-q", "-p", "symnlp-examples", "--example", "casadi_external", "--", str(out)],
        cwd=ROOT,
        check=True,
    )
    return out


def load(directory, name, opt="-O1"):
    """Compiles `<name>.c` into a shared library and loads it with `casadi.external`;
    returns the CasADi function and symx's record of it."""
    lib = directory / f"{name}.so"
    subprocess.run(
        [c_compiler(), "-std=c99", opt, "-ffp-contract=off", "-shared", "-fPIC",
         "-o", str(lib), str(directory / f"{name}.c"), "-lm"],
        check=True,
    )
    record = json.loads((directory / f"{name}.json").read_text())
    return casadi.external(name, str(lib)), record


def from_bits(hexes):
    return np.array([int(h, 16) for h in hexes], dtype=np.uint64).view(np.float64)


def assert_same_bits(got, want_hex, what):
    got = np.asarray(got, dtype=np.float64).ravel()
    want = from_bits(want_hex)
    assert got.shape == want.shape, what
    differ = np.nonzero(got.view(np.uint64) != want.view(np.uint64))[0]
    assert differ.size == 0, (
        f"{what}: {differ.size} entries differ, first at {differ[0]}: "
        f"CasADi {got[differ[0]]!r}, symx {want[differ[0]]!r}"
    )


def check_against_symx(f, record):
    """CasADi's evaluation of the loaded function equals symx's outputs bit for bit and
    has the output sparsity symx wrote."""
    inputs = [casadi.DM(from_bits(v)) for v in record["inputs"]]
    outputs = f.call(inputs)
    assert len(outputs) == len(record["outputs"])
    for k, (out, want, sp) in enumerate(zip(outputs, record["outputs"], record["sparsity_out"])):
        s = out.sparsity()
        assert (s.size1(), s.size2()) == (sp["nrow"], sp["ncol"]), f"output {k}: shape"
        assert list(s.colind()) == sp["colind"], f"output {k}: column pointers"
        assert list(s.row()) == sp["row"], f"output {k}: row indices"
        assert_same_bits(out.nonzeros(), want, f"{record['name']} output {k}")
    return outputs


def test_small_function_through_external(generated):
    f, record = load(generated, "small")
    assert (f.n_in(), f.n_out()) == (2, 2)
    assert [f.name_in(i) for i in range(2)] == ["x", "p"]
    assert [f.name_out(i) for i in range(2)] == ["y", "jac_y"]
    assert (f.size1_in(0), f.size1_in(1)) == (3, 1)
    y, jac = check_against_symx(f, record)

    # The same function built in CasADi's SX: the same elementary operations, which CasADi
    # may simplify or reorder when it builds the graph (e.g. the Jacobian's products), so
    # equal to a few ulps (relative 1e-14), not bit for bit.
    x = casadi.SX.sym("x", 3)
    p = casadi.SX.sym("p")
    ys = casadi.vertcat(
        x[0] * casadi.sin(x[1]) + p,
        casadi.exp(x[0] * x[2]) / (1 + x[1] * x[1]),
        casadi.sqrt(x[2] * x[2] + p) - casadi.atan2(x[0], p),
    )
    ref = casadi.Function("ref", [x, p], [ys, casadi.jacobian(ys, x)])
    y_ref, jac_ref = ref(*[from_bits(v) for v in record["inputs"]])
    np.testing.assert_allclose(np.array(y).ravel(), np.array(y_ref).ravel(), rtol=1e-14)
    np.testing.assert_allclose(
        np.array(casadi.densify(jac)), np.array(casadi.densify(jac_ref)), rtol=1e-14
    )


def test_gap_model_gradient_through_external(generated):
    # -O0: the gradient is one straight-line function of ~100 kB of C; optimising it only
    # lengthens the compile, and the values do not depend on the level without contraction.
    f, record = load(generated, "gap_grad_f", opt="-O0")
    assert (f.n_in(), f.n_out()) == (1, 1)
    assert f.size1_in(0) == len(record["inputs"][0])
    check_against_symx(f, record)
