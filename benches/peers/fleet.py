#!/usr/bin/env python3
"""A batch's joint fit solved by scipy.sparse: the same normal equations
tricept's `fleet` solves (one Gauss-Newton step of 10, 100 or 1000
machines x 80 poses: every machine's offsets and parameters, the batch
mean), exported by the `fleet_scale` example.

    cargo build --release -p tricept-benches --example fleet_scale
    python benches/peers/fleet.py                    # 10, 100, 1000 machines
    python benches/peers/fleet.py --machines 100 --repeats 5

For each size the script exports the step (`fleet_scale N --export DIR`:
the lower triangle of J^T J in Matrix Market, J^T b, and tricept's block
elimination's solution), reads it into scipy.sparse, and times
`scipy.sparse.linalg.spsolve` (SuperLU, COLAMD ordering, the default) and
`splu` with the minimum-degree ordering of A^T + A, and `spsolve` on the
equations scaled to a unit diagonal (as tricept's sparse Cholesky does
before it refines with J itself) (best of `--repeats`,
reading excluded). Against tricept it prints the time of one solve by each
of its kinds (`fleet_scale N --compare`: the same step), and the largest
difference of scipy's solution from tricept's, relative to each unknown's
size (never below 1e-6 of the largest). scipy has no sparse Cholesky of
its own (CHOLMOD needs scikit-sparse, not installed here).
"""

import argparse
import json
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.io
import scipy.sparse
import scipy.sparse.linalg

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "target" / "release" / "examples" / "fleet_scale"


def best(f, repeats):
    times = []
    out = None
    for _ in range(repeats):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return min(times), out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--machines", default="10,100,1000")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    for n in [int(x) for x in args.machines.split(",")]:
        with tempfile.TemporaryDirectory() as d:
            ours = json.loads(
                subprocess.run([EXAMPLE, str(n), "--compare", "--export", d], check=True, capture_output=True, text=True).stdout
            )
            lower = scipy.io.mmread(Path(d) / "normal.mtx").tocsc()
            rhs = np.loadtxt(Path(d) / "rhs.txt")
            reference = np.loadtxt(Path(d) / "solution.txt")
        normal = lower.tocsc()
        scale = np.abs(reference).max()

        def error(x):
            return float(np.max(np.abs(x - reference) / np.maximum(np.abs(reference), 1e-6 * scale)))

        t_spsolve, x = best(lambda: scipy.sparse.linalg.spsolve(normal, rhs), args.repeats)
        d = 1.0 / np.sqrt(normal.diagonal())
        scaled = scipy.sparse.diags(d) @ normal @ scipy.sparse.diags(d)
        t_scaled, x3 = best(lambda: d * scipy.sparse.linalg.spsolve(scaled.tocsc(), d * rhs), args.repeats)
        t_mmd, x2 = best(
            lambda: scipy.sparse.linalg.splu(normal, permc_spec="MMD_AT_PLUS_A").solve(rhs), args.repeats
        )
        kinds = {k[len("one_solve_"):-2]: v for k, v in ours.items() if k.startswith("one_solve_")}
        print(
            f"{n} machines: {normal.shape[0]} unknowns, {normal.nnz} stored non-zeros of J^T J (lower); "
            f"scipy spsolve {t_spsolve:.4f} s (vs tricept {error(x):.1e}), "
            f"spsolve of the unit-diagonal scaling {t_scaled:.4f} s ({error(x3):.1e}), "
            f"splu MMD(A^T+A) {t_mmd:.4f} s ({error(x2):.1e}); tricept one solve: "
            + ", ".join(f"{k} {v:.4f} s" for k, v in kinds.items())
        )


if __name__ == "__main__":
    main()
