#!/usr/bin/env bash
# Install the CasADi reference toolchain into the current user's Python (idempotent).
# Usage: bash benches/reference/setup.sh
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
PY="${PYTHON:-python3}"
if "$PY" -c 'import casadi, sys; sys.exit(0 if casadi.__version__ == "3.8.2" else 1)' 2>/dev/null; then
    echo "casadi $("$PY" -c 'import casadi; print(casadi.__version__)') already installed"
else
    "$PY" -m pip install --disable-pip-version-check -q -r "$HERE/requirements.txt"
fi
"$PY" -c 'import casadi, numpy; print("casadi", casadi.__version__, "numpy", numpy.__version__)'
