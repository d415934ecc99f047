"""The researcher's example runs headless and says what it should: the
calibration pays (after well under before, on a reference calibration the
first never saw), and the residuals are the stated sensor noise."""

import pathlib
import re
import subprocess
import sys

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "calibrate.py"


def test_the_example_runs_headless_and_calibration_pays(tmp_path):
    out = subprocess.run(
        [sys.executable, str(EXAMPLE), str(tmp_path)],
        capture_output=True,
        text=True,
        env={"MPLBACKEND": "Agg", "PATH": ""},
    )
    assert out.returncode == 0, out.stdout + out.stderr
    m = re.search(r"before ([0-9.]+) mm, after ([0-9.]+) mm", out.stdout)
    before, after = float(m.group(1)), float(m.group(2))
    assert before > 0.3 and after < 0.2 * before, out.stdout
    for name in ("phi", "theta", "s"):
        rms = float(re.search(rf"residual rms {name}: ([0-9.]+) sd", out.stdout).group(1))
        assert 0.5 < rms < 1.6, out.stdout
    for png in ("error_maps.png", "residuals.png"):
        assert (tmp_path / png).stat().st_size > 10_000
