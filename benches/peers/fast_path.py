#!/usr/bin/env python3
"""The Monte Carlo fast path of tricept's encoder study, in numpy.

The same algorithm as `LinearEstimator::run` (crates/study/src/fast.rs) on
the same matrices: per trial 14 standard normals z, dp = T z (T the 14 x 14
factor), d = dr0 - G dp (G the 147 x 14 plane map), the 49 norms |d_p| and
their mean and maximum, the mean after removing the best-fit translation,
and mu = (|truth - p*| on the held parameters + sum_u |offset_u - dp_u|) / 15.
Vectorised over batches of trials (numpy's matrix products use its BLAS on
every core).

    cargo run --release -p tricept-study --example fast_path_matrices -- fast_path.json
    python benches/peers/fast_path.py fast_path.json

The script times the numpy peer (wall and CPU time), then (unless
--no-rust) runs the criterion bench `cargo bench -p tricept-benches --bench
study -- fast_path` and prints the ratio of the two throughputs, measured
in one run. On a machine shared with other work, compare CPU time per trial
instead: `cargo run --release -p tricept-study --example fast_path_profile`
gives the Rust path's on one thread. It also
checks that its Monte Carlo means agree with the Rust ones the example
wrote (same algorithm, other random numbers: within 5 standard errors).
"""

import argparse
import json
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def load(path):
    d = json.load(open(path))
    T = np.array(d["factor"])
    G = np.array(d["plane_jacobian"])
    dr0 = np.array(d["plane_clean"])
    cols = d["columns"]
    truth, p_star = np.array(d["truth"]), np.array(d["p_star"])
    moving = np.zeros(len(truth), bool)
    moving[cols] = True
    offset = truth[cols] - p_star[cols]
    held = np.abs(truth - p_star)[~moving].sum()
    return T, G, dr0, offset, held, len(truth), d["rust"]


def trials(T, G, dr0, offset, held, n_params, z):
    """The four results of every trial of the standard normals z (n x q).

    The plane map is applied per component (G's x, y and z rows), so that
    the norms work on contiguous n x 49 arrays rather than on an axis of 3.
    """
    dp = z @ T.T
    mu = (held + np.abs(offset - dp).sum(axis=1)) / n_params
    d = [dr0[c::3] - dp @ G[c::3].T for c in range(3)]
    norms = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    e = [dc - dc.mean(axis=1, keepdims=True) for dc in d]
    touched = np.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).mean(axis=1)
    return mu, norms.mean(axis=1), norms.max(axis=1), touched


def run(model, n, batch, rng):
    T = model[0]
    out = []
    for start in range(0, n, batch):
        z = rng.standard_normal((min(batch, n - start), T.shape[0]))
        out.append(trials(*model, z))
    return [np.concatenate(c) for c in zip(*out)]


def rust_throughput():
    """criterion's throughput interval of the Rust fast path, trials/s."""
    cmd = ["cargo", "bench", "-p", "tricept-benches", "--bench", "study", "--", "fast_path"]
    print("running:", " ".join(cmd), flush=True)
    out = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=True).stdout
    m = re.search(r"thrpt:\s*\[([\d.]+) (\w)elem/s ([\d.]+) (\w)elem/s ([\d.]+) (\w)elem/s\]", out)
    if not m:
        sys.exit("could not read the bench's throughput:\n" + out)
    scale = {"K": 1e3, "M": 1e6, "G": 1e9}
    return [float(m.group(i)) * scale[m.group(i + 1)] for i in (1, 3, 5)]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("matrices", help="the JSON written by the fast_path_matrices example")
    ap.add_argument("--trials", type=int, default=1_000_000, help="trials per timed run")
    ap.add_argument("--repeats", type=int, default=3, help="timed runs per batch size (best kept)")
    ap.add_argument("--batches", default="1024,4096,16384,65536", help="batch sizes tried")
    ap.add_argument("--no-rust", action="store_true", help="do not run the Rust bench")
    a = ap.parse_args()
    *model, rust = load(a.matrices)
    rng = np.random.default_rng(1)

    # Same algorithm: the means agree with the Rust path's within Monte Carlo error.
    res = run(model, rust["trials"], 16384, rng)
    names = ["mu_mm", "plane_mean_mm", "plane_max_mm", "plane_touched_mean_mm"]
    for name, v in zip(names, res):
        r = rust["summary"][name]
        z = (v.mean() - r["mean"]) / np.hypot(v.std() / np.sqrt(len(v)), r["sd"] / np.sqrt(rust["trials"]))
        print(f"{name}: numpy mean {v.mean():.6g}, Rust {r['mean']:.6g} ({z:+.2f} standard errors)")
        if abs(z) > 5:
            sys.exit(f"{name}: the numpy peer does not reproduce the Rust fast path")

    from threadpoolctl import threadpool_info, threadpool_limits

    blas = [(i["internal_api"], i.get("architecture"), i["num_threads"]) for i in threadpool_info()]
    print(f"numpy {np.__version__}, BLAS {blas}")
    best = {}
    for threads in sorted({1, blas[0][2] if blas else 1}):
        with threadpool_limits(limits=threads):
            for batch in [int(b) for b in a.batches.split(",")]:
                times, cpu = [], []
                for _ in range(a.repeats):
                    t, c = time.perf_counter(), time.process_time()
                    run(model, a.trials, batch, rng)
                    times.append(time.perf_counter() - t)
                    cpu.append(time.process_time() - c)
                best[(threads, batch)] = a.trials / min(times)
                print(f"numpy, {threads} BLAS thread(s), batches of {batch}: "
                      f"{best[(threads, batch)] / 1e6:.3f} M trials/s (best of {a.repeats}), "
                      f"{min(cpu) / a.trials * 1e9:.0f} ns CPU per trial", flush=True)
    (threads, batch), numpy_rate = max(best.items(), key=lambda kv: kv[1])
    print(f"numpy peer: {numpy_rate / 1e6:.3f} M trials/s ({threads} BLAS thread(s), batches of {batch})")
    if a.no_rust:
        return
    low, mid, high = rust_throughput()
    print(f"Rust fast path (criterion): {low / 1e6:.2f} {mid / 1e6:.2f} {high / 1e6:.2f} M trials/s")
    print(f"ratio Rust / numpy: {low / numpy_rate:.1f} {mid / numpy_rate:.1f} {high / numpy_rate:.1f}")


if __name__ == "__main__":
    main()
