#!/usr/bin/env bash
# The Python package's tests from a clean clone: builds and installs the
# package into a fresh virtual environment (`pip install ./python`, which
# fetches maturin, and numpy, pytest, matplotlib and pandas from PyPI),
# builds the CLI the tests compare with, and runs pytest; then checks the
# type stubs against the installed package (`mypy.stubtest`) and a typed
# use of them (tests/typing/usage.py, with pandas-stubs), mypy from PyPI.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/python-venv
rm -rf "$venv"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install --quiet "./python[test]" mypy pandas-stubs
cargo build --quiet -p tricept-cli
# From the tests' own folder, so that `import tricept` is the installed
# package, not the source folder beside pyproject.toml.
cd python/tests
MPLBACKEND=Agg "../../$venv/bin/python" -m pytest -q -p no:cacheprovider .
# The stubs say what the installed package is, and accept what the docs
# promise (a DataFrame as data, a Machine as machine).
"../../$venv/bin/python" -m mypy.stubtest tricept
"../../$venv/bin/python" -m mypy --strict --warn-unused-ignores --no-incremental typing/usage.py
