"""Shared fixtures: the `tricept` binary of the repository (built by
`cargo build -p tricept-cli`, as `python/ci.sh` does) and a work directory."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    """Runs the CLI: ``cli(*args)`` returns the CompletedProcess."""
    exe = os.environ.get("TRICEPT_CLI", str(ROOT / "target" / "debug" / "tricept"))
    if not os.path.exists(exe):
        pytest.fail(f"the tricept binary is missing at {exe}: run `cargo build -p tricept-cli` (python/ci.sh does)")

    def run(*args, cwd=None):
        return subprocess.run([exe, *map(str, args)], capture_output=True, text=True, cwd=cwd)

    return run
