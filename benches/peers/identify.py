#!/usr/bin/env python3
"""The identification `tricept identify` runs, written with scipy (and
Ceres through pyceres when it is installed): the same estimator (exact
forward kinematics, the paper's 15 parameters with dyA3 held at zero, the
three sensor offsets, rows weighted by 1/sigma), on the same CSV files,
with an independent model (tricept_model.py, written from
docs/conventions.md).

    cargo build --release -p tricept-cli
    python benches/peers/identify.py                 # 80, 1000, 10000 poses
    python benches/peers/identify.py --sizes 80,1000 --repeats 3

For each size the script simulates a campaign with `tricept simulate`
(random poses, Table 2, the paper's noise), times `tricept identify --json
--no-robust` (the same estimator; the default gross-error screen is
something the peers do not do) process to process, and fits the same file
with each peer, timing the peer's own process work (reading the CSV and
fitting, without the interpreter's start). It prints the time ratios and
the accuracy: the largest distance between the peer's optimum and
tricept's over the 14 identifiable parameters, in tricept's standard
deviations, and each optimum's chi-square under the peer's model (the lower
is the better optimum), and checks tricept's standard deviations against
the peer's (J^T J)^-1.
"""

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

sys.path.insert(0, str(Path(__file__).resolve().parent))
import tricept_model as tm  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
MACHINE = ROOT / "fixtures/machines/tricept-paper.json"
HELD = tm.NAMES.index("dyA3")
FREE = [k for k in range(15) if k != HELD]
# The logged noise of the paper's sensors: 0.8 arcsec, 0.5 um, mean of 3.
SIGMA = np.array([np.radians(0.8 / 3600), np.radians(0.8 / 3600), 0.5e-3]) / np.sqrt(3)


class Problem:
    """Weighted residuals (y - g(q; p) - c) / sigma of a data set over
    x = [14 free parameters, 3 offsets], FK warm-started from the last
    evaluation (as tricept's Gauss-Newton does)."""

    def __init__(self, q, y, machine, free=FREE):
        self.q, self.y, self.m, self.free = q, y, machine, free
        self.seeds = None
        self.cache = (None, None)
        self.evaluations = 0

    def params(self, x):
        p = np.zeros(15)
        p[self.free] = x[: len(self.free)]
        return p

    def joints(self, x):
        if self.cache[0] is not None and np.array_equal(self.cache[0], x):
            return self.cache[1]
        self.tried = x.copy()
        j = tm.forward(self.q, self.params(x), self.m, seeds=self.seeds)
        self.seeds, self.cache = j, (x.copy(), j)
        self.evaluations += 1
        return j

    def residuals(self, x):
        return ((self.y - self.joints(x) - x[len(self.free):]) / SIGMA).ravel()

    def jacobian(self, x):
        j = self.joints(x)
        dj = tm.jacobian(j, self.params(x), self.m)[:, :, self.free]
        n = len(j)
        jac = np.empty((n, 3, len(self.free) + 3))
        jac[:, :, : len(self.free)] = -dj
        jac[:, :, len(self.free):] = -np.eye(3)
        return (jac / SIGMA[None, :, None]).reshape(3 * n, -1)

    def start(self):
        x = np.zeros(len(self.free) + 3)
        x[len(self.free):] = (self.y - self.joints(x)).mean(axis=0)
        return x


def scipy_fit(q, y, m, method, jac):
    pr = Problem(q, y, m)
    r = least_squares(pr.residuals, pr.start(), jac=pr.jacobian if jac == "analytic" else jac,
                      method=method)
    return r.x, pr.evaluations


def ceres_fit(q, y, m):
    import pyceres

    pr = Problem(q, y, m)
    x = pr.start()
    nf = len(FREE)
    p, c = x[:nf].copy(), x[nf:].copy()

    class Cost(pyceres.CostFunction):
        def __init__(self):
            super().__init__()
            self.set_num_residuals(3 * len(q))
            self.set_parameter_block_sizes([nf, 3])

        def Evaluate(self, parameters, residuals, jacobians):
            xx = np.concatenate([parameters[0], parameters[1]])
            residuals[:] = pr.residuals(xx)
            if jacobians is not None:
                jac = pr.jacobian(xx)
                if jacobians[0] is not None:
                    jacobians[0][:] = jac[:, :nf].ravel()
                if jacobians[1] is not None:
                    jacobians[1][:] = jac[:, nf:].ravel()
            return True

    problem = pyceres.Problem()
    problem.add_residual_block(Cost(), None, [p, c])
    options = pyceres.SolverOptions()
    options.linear_solver_type = pyceres.LinearSolverType.DENSE_QR
    summary = pyceres.SolverSummary()
    pyceres.solve(options, problem, summary)
    return np.concatenate([p, c]), pr.evaluations


def tricept(csv, binary, repeats):
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        out = subprocess.run([str(binary), "identify", "--data", str(csv), "--json", "--no-robust"],
                             capture_output=True, text=True)
        best = min(best, time.perf_counter() - t)
    if out.returncode not in (0, 3):
        sys.exit(f"tricept identify failed: {out.stderr}")
    j = json.loads(out.stdout)
    x = np.array([j[tm.NAMES[k]] for k in FREE] +
                 [j["offsets"]["phi_rad"], j["offsets"]["theta_rad"], j["offsets"]["s_mm"]])
    sd = np.array([j["std_dev"][tm.NAMES[k]] for k in FREE])
    return x, sd, best, j["residuals"]["chi_square"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="80,1000,10000", help="poses per campaign")
    ap.add_argument("--repeats", type=int, default=3, help="timed runs of each fit (best kept)")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--tricept", default=str(ROOT / "target/release/tricept"), help="the tricept binary")
    ap.add_argument("--peers", default="lm,trf-2point,ceres",
                    help="lm (scipy LM, analytic Jacobian), trf-2point (scipy trf, 2-point differences), ceres (pyceres, analytic Jacobian)")
    a = ap.parse_args()
    m = tm.Machine(MACHINE)
    peers = a.peers.split(",")
    if "ceres" in peers:
        try:
            import pyceres  # noqa: F401
        except ImportError:
            print("pyceres is not installed: Ceres skipped (pip install -r requirements-ceres.txt)")
            peers.remove("ceres")
    fits = {
        "lm": lambda q, y: scipy_fit(q, y, m, "lm", "analytic"),
        "trf-2point": lambda q, y: scipy_fit(q, y, m, "trf", "2-point"),
        "ceres": lambda q, y: ceres_fit(q, y, m),
    }
    # The interpreter's start and imports, which a peer's process adds.
    t = time.perf_counter()
    subprocess.run([sys.executable, "-c", "import numpy, scipy.optimize"], check=True)
    startup = time.perf_counter() - t
    print(f"python start and imports: {startup:.3f} s")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in [int(s) for s in a.sizes.split(",")]:
            csv = Path(tmp) / f"random{n}.csv"
            subprocess.run([a.tricept, "simulate", "--poses", f"random:{n},{a.seed}", "--seed", str(a.seed),
                            "--out", str(csv)], check=True, capture_output=True)
            xt, sd, t_tricept, chi2_tricept = tricept(csv, a.tricept, a.repeats)
            q, y = tm.read_csv(csv)
            pr = Problem(q, y, m)
            chi2 = lambda x: float(np.sum(pr.residuals(x) ** 2))  # noqa: E731
            # tricept's standard deviations against the peer model's (J^T J)^-1 at tricept's optimum.
            jac = pr.jacobian(xt)
            cov = np.linalg.inv(jac.T @ jac)
            sd_peer = np.sqrt(np.diag(cov))[: len(FREE)]
            sd_check = np.max(np.abs(sd / sd_peer - 1))
            print(f"\n{n} poses: tricept identify {t_tricept:.3f} s (process), chi-square {chi2_tricept:.6f} "
                  f"(peer model at tricept's estimate: {chi2(xt):.6f}); its sd against the peer's (J^T J)^-1: "
                  f"{sd_check:.1e} relative", flush=True)
            for name in peers:
                best, x, evals = np.inf, None, 0
                for _ in range(a.repeats):
                    t = time.perf_counter()
                    q, y = tm.read_csv(csv)
                    x, evals = fits[name](q, y)
                    best = min(best, time.perf_counter() - t)
                dist = np.max(np.abs(x[: len(FREE)] - xt[: len(FREE)]) / sd)
                excess = chi2(x) - chi2(xt)
                print(f"  {name}: {best:.3f} s ({best / t_tricept:.1f} x tricept; process to process "
                      f"{(best + startup) / t_tricept:.1f} x), {evals} model evaluations, "
                      f"optimum {dist:.1e} sd from tricept's, chi-square {excess:+.2e} against tricept's",
                      flush=True)
                rows.append({"poses": n, "peer": name, "seconds": best, "tricept_seconds": t_tricept,
                             "ratio": best / t_tricept, "process_ratio": (best + startup) / t_tricept,
                             "distance_sd": dist, "chi2_minus_tricept": excess, "sd_check": sd_check})
            if "lm" in peers:
                # What the user gets without a rank decision: dyA3 free too.
                pr_all = Problem(q, y, m, free=list(range(15)))
                try:
                    r = least_squares(pr_all.residuals, pr_all.start(), jac=pr_all.jacobian, method="lm")
                    print(f"  lm with dyA3 free: status {r.status} ({r.message!r}), dyA3 = {r.x[HELD]:+.4f} mm "
                          f"(truth +0.2), no warning", flush=True)
                except Exception as e:  # what the user sees
                    print(f"  lm with dyA3 free: fails after {pr_all.evaluations} model evaluations: "
                          f"{type(e).__name__}: {e} (in the forward kinematics at the step to dyA3 = "
                          f"{pr_all.tried[HELD]:+.3g} mm)", flush=True)
    print("\n| poses | peer | peer (read + fit) | tricept identify (process) | ratio | process to process "
          "| optimum distance (sd) | chi-square - tricept's |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['poses']} | {r['peer']} | {r['seconds']:.3f} s | {r['tricept_seconds']:.3f} s | "
              f"{r['ratio']:.1f}x | {r['process_ratio']:.0f}x | {r['distance_sd']:.1e} | "
              f"{r['chi2_minus_tricept']:+.1e} |")


if __name__ == "__main__":
    main()
