"""A million-point inverse kinematics from numpy against `tricept ik
--input` of the same points, measured in one run (docs/performance.md).

Usage: python python/benches/ik_million.py [PATH/TO/tricept] [N]
The CLI should be a release build (`cargo build --release -p tricept-cli`),
as the Python package is (`pip install ./python` builds in release).
"""

import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import tricept


def main():
    exe = sys.argv[1] if len(sys.argv) > 1 else "target/release/tricept"
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 1_000_000
    rng = np.random.default_rng(1)
    r = 300.0 * np.sqrt(rng.uniform(size=n))
    a = rng.uniform(0, 2 * np.pi, size=n)
    pts = np.column_stack([r * np.cos(a), r * np.sin(a), rng.uniform(650.0, 850.0, size=n)])
    m = tricept.Machine.paper()
    m.ik(pts[:1000])  # warm-up
    t0 = time.perf_counter()
    q = m.ik(pts)
    t_py = time.perf_counter() - t0
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "p.csv")
        np.savetxt(path, pts, delimiter=",", header="x,y,z", comments="", fmt="%.17g")
        t0 = time.perf_counter()
        out = subprocess.run([exe, "ik", "--input", path], capture_output=True)
        t_cli = time.perf_counter() - t0
        assert out.returncode == 0, out.stderr
    print(f"{n} points: numpy {t_py:.3f} s ({n / t_py / 1e6:.2f} M points/s), "
          f"tricept ik --input {t_cli:.3f} s ({n / t_cli / 1e6:.2f} M points/s), "
          f"ratio {t_cli / t_py:.1f}x; q shape {q.shape}")


if __name__ == "__main__":
    main()
