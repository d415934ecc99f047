#!/usr/bin/env bash
# The Python package's tests from a clean clone: builds and installs the
# package into a fresh virtual environment (`pip install ./python`, which
# fetches maturin, and numpy, pytest and matplotlib from PyPI), builds the
# CLI the tests compare with, and runs pytest.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/python-venv
rm -rf "$venv"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install --quiet "./python[test]"
cargo build --quiet -p tricept-cli
cd python
MPLBACKEND=Agg "../$venv/bin/python" -m pytest -q tests
