"""The type stubs cover every public name of the native module, with no stale entries."""
import ast
import pathlib

import symnlp
from symnlp import _symnlp

STUB = pathlib.Path(symnlp.__file__).with_name("_symnlp.pyi")


def test_stub_names_match_the_module():
    tree = ast.parse(STUB.read_text())
    stubbed = {
        n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))
    }
    public = {n for n in dir(_symnlp) if not n.startswith("_")}
    assert public - stubbed == set(), "not in the stubs"
    assert stubbed - public == set(), "stale in the stubs"


def test_docstrings_everywhere():
    for name in dir(_symnlp):
        if not name.startswith("_"):
            assert getattr(_symnlp, name).__doc__, name
