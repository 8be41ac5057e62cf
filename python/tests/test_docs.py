"""The Python blocks of docs/python.md that are complete programs run as written."""
import pathlib
import re

DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "python.md"


def blocks(section):
    """The ```python blocks of the `## ` section whose heading starts with `section`."""
    text = DOC.read_text()
    start = text.index("\n## " + section)
    end = text.find("\n## ", start + 1)
    return re.findall(r"```python\n(.*?)```", text[start:end if end > 0 else None], re.S)


def test_first_problem_block_runs():
    (code,) = blocks("First problem")
    scope = {}
    exec(compile(code, "docs/python.md", "exec"), scope)
    assert abs(scope["sol"].objective - 17.0140173) < 1e-6


def test_optimal_control_blocks_run():
    code = blocks("Optimal control")
    assert len(code) == 2
    scope = {}
    exec(compile(code[0], "docs/python.md", "exec"), scope)
    assert abs(scope["traj"].objective - 3.732969410715394) < 1e-6  # the printed value
    exec(compile(code[1], "docs/python.md", "exec"), scope)
    assert scope["run"]["all_succeeded"] and abs(scope["run"]["states"][-1][0]) < 1e-3
    assert scope["report"]["success"]
