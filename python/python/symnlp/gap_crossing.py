"""The quadruped gap-crossing planner (the Rust crate ``gap_crossing``).

``solve(scenario)`` takes a scenario as a dict (the scenario file's schema; missing
fields take the defaults), a path to a ``.toml``/``.json`` scenario file, or ``None`` for
the default scenario, and returns the plan as a dict in the solution-file schema of
docs/gap-crossing.md. ``check(plan)`` re-checks a plan (dict or path) independently.
"""
from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Mapping, Optional, Union

from . import _symnlp

__all__ = ["solve", "check", "CheckReport"]


def solve(
    scenario: Union[None, Mapping[str, Any], str, os.PathLike] = None,
    solver: str = "ipm",
    options: Optional[Mapping[str, Any]] = None,
) -> Dict[str, Any]:
    """Plans a gap crossing; returns the solution file as a dict.

    The dict's ``solver.status`` word tells whether a valid plan was found; the key
    ``"solved"`` (added here) is ``True`` only then. ``options`` are the back end's options
    by their IPOPT names. Raises ``symnlp.BuildError`` on an invalid scenario.
    """
    opts = [f"{k}={_option_text(v)}" for k, v in (options or {}).items()]
    if scenario is None:
        status, solved, text = _symnlp.gap_crossing_solve(None, None, solver, opts)
    elif isinstance(scenario, (str, os.PathLike)):
        status, solved, text = _symnlp.gap_crossing_solve(None, os.fspath(scenario), solver, opts)
    else:
        status, solved, text = _symnlp.gap_crossing_solve(json.dumps(dict(scenario)), None, solver, opts)
    plan = json.loads(text)
    plan["solved"] = solved
    plan["status"] = status
    return plan


class CheckReport:
    """The independent checker's verdict on a plan."""

    def __init__(self, ok: bool, summary: str, violations: List[str]):
        self.ok = ok
        self.summary = summary
        self.violations = violations

    def __bool__(self) -> bool:
        return self.ok

    def __repr__(self) -> str:
        return f"CheckReport(ok={self.ok}, summary={self.summary!r}, violations={len(self.violations)})"


def check(plan: Union[Mapping[str, Any], str, os.PathLike]) -> CheckReport:
    """Checks a plan (a dict from ``solve`` or a solution file path) against the model."""
    if isinstance(plan, (str, os.PathLike)):
        with open(plan, encoding="utf-8") as f:
            text = f.read()
    else:
        data = {k: v for k, v in plan.items() if k not in ("solved", "status")}
        text = json.dumps(data)
    ok, summary, violations = _symnlp.gap_crossing_check(text)
    return CheckReport(ok, summary, violations)


def _option_text(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    return str(v)
