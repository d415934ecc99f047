"""A calibration from simulated data, as a researcher would script it.

1. Simulate two campaigns of the Table 1 machine with the paper's Table 2
   errors (`tricept.simulate`): one to calibrate from, one held out.
2. Calibrate from the first (`tricept.identify`, from column arrays); its
   calibrated machine (`Calibration.machine`) is used in memory.
3. Error maps over the workspace's mid plane, before and after: the
   platform error of commanding the machine with nominal commands (before)
   and with the calibration's commands (after), both measured on a second,
   independent calibration from the held-out campaign (the best estimate of
   the real machine that the first calibration never saw).
4. Residual plots: the logged readings minus what the calibrated machine
   predicts at the logged commands (with the identified sensor offsets),
   in units of the stated sensor noise.

Run: ``python examples/calibrate.py [OUT_DIR]`` (figures as PNG; the Agg
backend needs no display). Prints the rms errors before and after, mm.
"""

import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import tricept  # noqa: E402


def platform_error_mm(true_machine, commanding_machine, targets):
    """Where the true machine puts the platform when commanded with
    `commanding_machine`'s leg commands for `targets`, minus the targets."""
    q = commanding_machine.ik(targets)[:, :3]
    return true_machine.fk(q)[:, :3] - targets


def main(out_dir):
    os.makedirs(out_dir, exist_ok=True)
    calibration_data = tricept.simulate(poses="random:80,1", seed=1)
    held_out = tricept.simulate(poses="random:80,2", seed=2)

    c = tricept.identify(calibration_data)
    print(f"calibration: exit code {c.exit_code}")
    if c.exit_code != 0:
        print(c.report())
        return 1
    # The calibrated machines in memory: no file needed.
    calibrated = c.machine
    reference = tricept.identify(held_out).machine
    nominal = tricept.Machine.paper()

    # Error maps on the mid plane.
    r = np.linspace(-300, 300, 41)
    x, y = np.meshgrid(r, r)
    inside = x**2 + y**2 <= 300.0**2
    targets = np.column_stack([x[inside], y[inside], np.full(inside.sum(), 750.0)])
    before = np.linalg.norm(platform_error_mm(reference, nominal, targets), axis=1)
    after = np.linalg.norm(platform_error_mm(reference, calibrated, targets), axis=1)
    rms = lambda e: float(np.sqrt(np.mean(e**2)))  # noqa: E731
    print(f"platform error rms: before {rms(before):.4f} mm, after {rms(after):.4f} mm")
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.5), constrained_layout=True)
    for ax, err, title in ((axes[0], before, "before"), (axes[1], after, "after")):
        sc = ax.scatter(targets[:, 0], targets[:, 1], c=err * 1000.0, s=12, cmap="viridis")
        ax.set_title(f"{title} calibration: rms {rms(err) * 1000:.1f} um")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_aspect("equal")
        fig.colorbar(sc, ax=ax, label="platform error (um)")
    fig.savefig(os.path.join(out_dir, "error_maps.png"), dpi=80)
    plt.close(fig)

    # Residuals at the logged commands.
    report = json.loads(c.to_json())
    offsets = report["offsets"]
    q = np.column_stack([calibration_data[k] for k in ("q1", "q2", "q3")])
    predicted = calibrated.fk(q)
    noise_rad = 0.8 / 206264.806 / np.sqrt(3.0)
    noise_mm = 0.5e-3 / np.sqrt(3.0)
    residuals = {
        "phi": (calibration_data["phi"] - predicted[:, 3] - offsets["phi_rad"]) / noise_rad,
        "theta": (calibration_data["theta"] - predicted[:, 4] - offsets["theta_rad"]) / noise_rad,
        "s": (calibration_data["s"] - predicted[:, 5] - offsets["s_mm"]) / noise_mm,
    }
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.5), constrained_layout=True)
    for ax, (name, res) in zip(axes, residuals.items()):
        ax.plot(res, ".", ms=4)
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_title(f"{name}: rms {np.sqrt(np.mean(res**2)):.2f} sd")
        ax.set_xlabel("pose")
        ax.set_ylabel("residual / stated noise")
    fig.savefig(os.path.join(out_dir, "residuals.png"), dpi=80)
    plt.close(fig)
    for name, res in residuals.items():
        print(f"residual rms {name}: {np.sqrt(np.mean(res**2)):.2f} sd")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "calibrate-example"))
