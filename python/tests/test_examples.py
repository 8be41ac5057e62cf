"""The examples of docs/python.md run and reach their goals (they assert success)."""
import pathlib
import runpy

import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("name", ["hanging_chain.py", "cartpole_mpc.py"])
def test_example_runs(name, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # the chain example writes its plot here
    scope = runpy.run_path(str(EXAMPLES / name), run_name="__main__")
    out = capsys.readouterr().out
    assert out
    if name == "cartpole_mpc.py":
        # The loop stabilises the pole: from 0.3 rad to (nearly) upright in 2 s.
        assert abs(scope["x"][1]) < 1e-2
    else:
        # Raising the right end raises the chain: the energy grows with the height.
        energies = [c[2] for c in scope["chains"]]
        assert energies == sorted(energies)
