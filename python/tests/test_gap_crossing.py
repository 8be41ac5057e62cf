"""The gap-crossing planner from Python: solves, checks, and agrees with the Rust CLI."""
import json
import pathlib
import subprocess

import pytest

import symnlp
from symnlp import gap_crossing

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def default_plan():
    return gap_crossing.solve()


def test_default_scenario_solves_and_checks(default_plan):
    plan = default_plan
    assert plan["solved"], plan["status"]
    report = gap_crossing.check(plan)
    assert report.ok, report.violations
    assert "OK" in report.summary


def test_dict_scenario_gives_the_same_plan(default_plan):
    # The solution file carries its scenario: solving it again from the dict gives the
    # same plan, bit for bit (solves are deterministic).
    again = gap_crossing.solve(default_plan["scenario"])
    assert again["solver"]["objective"] == default_plan["solver"]["objective"]


def test_file_round_trip_and_check_detects_tampering(tmp_path, default_plan):
    data = {k: v for k, v in default_plan.items() if k not in ("solved", "status")}
    p = tmp_path / "solution.json"
    p.write_text(json.dumps(data))
    assert gap_crossing.check(p).ok
    bad = json.loads(json.dumps(data))
    bad["stances"] = _shift_first_number(bad["stances"])
    report = gap_crossing.check(bad)
    assert not report.ok and report.violations


def _shift_first_number(obj):
    """A copy of `obj` with the first float found (depth first) increased by 0.5."""
    done = [False]

    def walk(o):
        if done[0]:
            return o
        if isinstance(o, float):
            done[0] = True
            return o + 0.5
        if isinstance(o, list):
            return [walk(v) for v in o]
        if isinstance(o, dict):
            return {k: walk(v) for k, v in o.items()}
        return o

    return walk(obj)


def test_bad_input_is_a_clear_error():
    with pytest.raises(symnlp.BuildError, match="n_step"):
        gap_crossing.solve({"n_step": -3})
    with pytest.raises(symnlp.OptionError, match="toll"):
        gap_crossing.solve(options={"toll": 1})


def test_same_objective_as_the_cli(tmp_path, default_plan):
    exe = ROOT / "target" / "release" / "gap-crossing"
    if not exe.exists():
        pytest.skip("the release CLI is built by `cargo test --workspace --release`")
    subprocess.run([str(exe), "solve", "--out", str(tmp_path)], check=True, capture_output=True)
    cli = json.loads((tmp_path / "solution.json").read_text())
    assert cli["solver"]["objective"] == default_plan["solver"]["objective"]
