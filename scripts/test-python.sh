#!/usr/bin/env bash
# Runs the Python package's pytest suite in a virtual environment under .venv (created on
# first use; re-runs reuse it and only rebuild what changed). The README's test command runs
# it after `cargo test --workspace --release`, whose release artefacts the package build
# reuses. Extra arguments go to pytest, e.g. `scripts/test-python.sh -k hs071`.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== Python: .venv, the symnlp package, pytest"
PY="${PYTHON:-python3}"
if [ ! -x .venv/bin/python ]; then
    "$PY" -m venv .venv
fi
export PATH="$PWD/.venv/bin:$PATH" # the maturin build backend runs the `maturin` command
PIP=(.venv/bin/python -m pip --disable-pip-version-check -q)
"${PIP[@]}" install -r python/requirements-test.txt
# maturin is installed above, so the build needs no isolated environment (fast re-runs);
# the release artefacts of the cargo run above are reused.
"${PIP[@]}" install --no-build-isolation --force-reinstall --no-deps ./python
.venv/bin/python -m pytest -q python/tests "$@"
