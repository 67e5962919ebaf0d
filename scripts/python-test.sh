#!/usr/bin/env bash
# The Python package (crates/verne-py): builds it with maturin into a virtual environment this
# script makes (maturin, numpy and pytest from the Python registry), builds the `verne` command
# (the tests' oracle), and runs crates/verne-py/tests and the package's doctests.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
VENV="$ROOT/target/py-venv"
PY="$(command -v python3)"
[ -x "$VENV/bin/python" ] || "$PY" -m venv "$VENV"
"$VENV/bin/python" -m pip install -q --upgrade pip >/dev/null
"$VENV/bin/python" -m pip install -q "maturin>=1.5,<2" numpy pytest
cargo build --release -q -p verne-cli
export VIRTUAL_ENV="$VENV"
(cd "$ROOT/crates/verne-py" && "$VENV/bin/maturin" develop --release -q)
export VERNE_BIN="$ROOT/target/release/verne"
"$VENV/bin/python" -m pytest -q "$ROOT/crates/verne-py/tests" \
    --doctest-modules "$ROOT/crates/verne-py/python/verne/__init__.py" \
    --doctest-glob python.md "$ROOT/docs/python.md"
