"""What the type stubs promise, checked by mypy in python/ci.sh (with
pandas-stubs): a DataFrame is data, a Machine is a machine, one effect
may be a string; what they refuse is marked with the error mypy must
report (`--warn-unused-ignores` fails the run when it does not)."""

import numpy as np
import pandas as pd

import tricept


def calibrate(frame: pd.DataFrame) -> float:
    c: tricept.Calibration = tricept.identify(frame, readings_per_pose=3)
    m: tricept.Machine = c.machine
    q = m.ik(np.zeros((1, 3)))
    r: tricept.CheckResult = tricept.check(m, {"q1": np.zeros(3)}, history="h.jsonl")
    d: tricept.Diagnosis = tricept.diagnose(frame, machine=m)
    data = tricept.simulate(machine=m, effects='{"effect":"leg-lead","ppm":[1,2,3]}', revisit=2)
    print(r.verdict, d.causes, tricept.__version__, data["q1"].shape)
    return float(q[0, 0])


def refused() -> None:
    tricept.identify(5)  # type: ignore[arg-type]
    tricept.identify("d.csv", seed=1)  # type: ignore[call-arg]
    tricept.Machine.paper().ik(np.zeros((1, 3))).shape = "x"  # type: ignore[assignment]
