"""A Python door that behaves like Python: errors of the kinds Python code
expects (InputError for bad values, the OSError subclass for the file
system, MemoryError for memory, all importable and picklable), results and
machines that pickle and round-trip, machines given as objects, reprs that
say what they hold, array rows named as rows, and the package's version."""

import concurrent.futures
import importlib.metadata
import json
import os
import pathlib
import pickle
import stat
import subprocess
import sys

import numpy as np
import pytest

import tricept

ROOT = pathlib.Path(__file__).resolve().parents[2]
GRID = ROOT / "fixtures" / "data" / "table2-grid-seed1.csv"
HIDDEN = ROOT / "fixtures" / "data" / "diagnose-hidden-effect.csv"


def columns(path):
    lines = [l for l in pathlib.Path(path).read_text().splitlines() if l and not l.startswith("#")]
    header = lines[0].split(",")
    rows = [l.split(",") for l in lines[1:]]
    return {h: np.array([float(r[j]) for r in rows]) for j, h in enumerate(header)}


def raise_input_error(message):
    """A worker's failure (run in another process)."""
    tricept.identify({"q1": [1.0], "q2": [1.0, 2.0]})


def test_the_version_is_the_installed_one():
    assert tricept.__version__ == importlib.metadata.version("tricept")


def test_the_exceptions_are_the_packages_own_and_pickle():
    for cls, args in ((tricept.InputError, ("bad",)), (tricept.UntrustedError, ("refused", 3))):
        assert cls.__module__ == "tricept"
        e = pickle.loads(pickle.dumps(cls(*args)))
        assert type(e) is cls and e.args == args
    assert tricept.UntrustedError("refused", 4).exit_code == 4
    assert issubclass(tricept.InputError, ValueError)
    assert issubclass(tricept.UntrustedError, RuntimeError)
    # A worker process's InputError reaches the caller as itself.
    with concurrent.futures.ProcessPoolExecutor(max_workers=1) as pool:
        with pytest.raises(tricept.InputError, match="different lengths"):
            pool.submit(raise_input_error, "x").result()


def test_options_out_of_range_and_machines_of_the_wrong_kind_are_input_errors():
    for options, needle in (
        ({"readings_per_pose": -1}, "readings_per_pose"),
        ({"readings_per_pose": 2**40}, "readings_per_pose"),
        ({"readings_per_pose": 0}, "readings_per_pose"),
        ({"tolerance_mm": -1.0}, "^tolerance_mm: the manufacturing tolerance"),
        ({"angle_noise_arcsec": -2.0}, "^angle_noise_arcsec: must be a positive number"),
    ):
        with pytest.raises(tricept.InputError, match=needle):
            tricept.identify(GRID, **options)
    for options in ({"seed": -1}, {"seed": 2**64}, {"revisit": -1}):
        with pytest.raises(tricept.InputError, match=list(options)[0]):
            tricept.simulate(poses="random:10,1", **options)
    with pytest.raises(tricept.InputError, match="machine: expected a machine file"):
        tricept.identify(GRID, machine=5)
    with pytest.raises(tricept.InputError, match="machine: expected a machine file"):
        tricept.simulate(machine=[1, 2])
    with pytest.raises(TypeError, match="seed"):
        tricept.simulate(seed="3")


def test_file_system_failures_are_os_errors(tmp_path):
    c = tricept.identify(GRID)
    with pytest.raises(FileNotFoundError) as e:
        c.write_machine(tmp_path / "no" / "such" / "cal.json")
    assert e.value.filename.endswith("cal.json")
    assert not (tmp_path / "no").exists()
    with pytest.raises(FileNotFoundError):
        tricept.Machine.load(tmp_path / "nothing.json")
    with pytest.raises(FileNotFoundError):
        tricept.identify(tmp_path / "nothing.csv")
    c.write_machine(tmp_path / "cal.json")
    with pytest.raises(FileNotFoundError):
        tricept.check(tmp_path / "cal.json", GRID, history=tmp_path / "no" / "h.jsonl")
    # A named pipe is not replaced by a machine file: refused as input.
    pipe = tmp_path / "pipe.json"
    os.mkfifo(pipe)
    with pytest.raises(tricept.InputError, match="named pipe"):
        c.write_machine(pipe)
    assert stat.S_ISFIFO(os.stat(pipe).st_mode)


def test_a_bad_array_row_is_named_as_the_array_row():
    data = columns(GRID)
    data["s"] = data["s"].astype(object)
    data["s"][5] = "x"
    with pytest.raises(tricept.InputError) as e:
        tricept.identify(data)
    message = str(e.value)
    assert "row 5" in message and "`s`" in message, message
    assert "line" not in message, message
    data = columns(GRID)
    data["q1"][7] = 1e4  # beyond the stroke
    with pytest.raises(tricept.InputError, match="row 7"):
        tricept.diagnose(data)
    pd = pytest.importorskip("pandas")
    frame = pd.DataFrame(columns(GRID))
    frame.loc[5, "theta"] = np.nan
    with pytest.raises(tricept.InputError, match="row 5, column `theta`"):
        tricept.identify(frame)
    assert tricept.identify(pd.DataFrame(columns(GRID))).exit_code == 0


def test_a_calibration_pickles_and_round_trips_with_its_machine_and_file(tmp_path):
    c = tricept.identify(GRID)
    back = pickle.loads(pickle.dumps(c))
    assert back.exit_code == c.exit_code
    assert back.names == c.names and back.estimates == c.estimates and back.sd == c.sd
    np.testing.assert_array_equal(back.covariance, c.covariance)
    assert back.to_json() == c.to_json() and back.report() == c.report()
    assert back.warnings == c.warnings
    assert repr(back) == repr(c)
    assert pickle.loads(pickle.dumps(back)).to_json() == c.to_json()
    # The file written from the copy loads as the one written from the
    # original and commands the same.
    c.write_machine(tmp_path / "live.json")
    back.write_machine(tmp_path / "copy.json")
    live, copy = tricept.Machine.load(tmp_path / "live.json"), tricept.Machine.load(tmp_path / "copy.json")
    p = np.array([[10.0, -20.0, 760.0], [150.0, 100.0, 700.0]])
    np.testing.assert_array_equal(live.ik(p), copy.ik(p))
    strip = lambda m: {k: v for k, v in json.loads(m.to_json())["calibration"].items() if k not in ("date", "seal")}
    assert strip(live) == strip(copy)
    # The machine in memory is the written file's.
    np.testing.assert_array_equal(c.machine.ik(p), live.ik(p))
    np.testing.assert_array_equal(back.machine.ik(p), live.ik(p))
    assert c.machine.calibration == "identify"
    # An untrusted calibration's copy keeps the rule.
    hidden = pickle.loads(pickle.dumps(tricept.identify(HIDDEN)))
    with pytest.raises(tricept.UntrustedError) as e:
        hidden.write_machine(tmp_path / "no.json")
    assert e.value.exit_code == 3 and not (tmp_path / "no.json").exists()
    hidden.write_machine(tmp_path / "forced.json", force=True)
    assert json.loads((tmp_path / "forced.json").read_text())["calibration"]["forced"] is True
    # From arrays: no file (no data file to record), but a machine.
    arrays = tricept.identify(columns(GRID))
    from_arrays = pickle.loads(pickle.dumps(arrays))
    with pytest.raises(tricept.InputError, match="data file"):
        from_arrays.write_machine(tmp_path / "arrays.json")
    np.testing.assert_allclose(arrays.machine.ik(p), live.ik(p), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(from_arrays.machine.ik(p), arrays.machine.ik(p))
    assert arrays.machine.calibration is None


def test_machines_pickle_are_accepted_as_machine_and_say_what_they_are(tmp_path):
    c = tricept.identify(GRID)
    c.write_machine(tmp_path / "cal.json")
    m = tricept.Machine.load(tmp_path / "cal.json")
    back = pickle.loads(pickle.dumps(m))
    p = np.array([[0.0, 0.0, 750.0]])
    np.testing.assert_array_equal(back.ik(p), m.ik(p))
    assert back.source == m.source and back.to_json() == m.to_json()
    assert "calibrated by identify" in repr(m) and "cal.json" in repr(m)
    assert "calibrated" not in repr(tricept.Machine.paper())
    # machine= takes a Machine as it takes the file.
    day = tricept.simulate(machine=m, poses="random:20,9", seed=4)
    from_file = tricept.check(tmp_path / "cal.json", day)
    from_object = tricept.check(m, day)
    assert from_object.to_json() == from_file.to_json()
    recal_file = tricept.identify(GRID, machine=tmp_path / "cal.json")
    recal_object = tricept.identify(GRID, machine=back, angle_noise_arcsec=0.8)
    assert recal_object.estimates == recal_file.estimates
    # A calibration's machine checks a campaign as its file does.
    by_memory = json.loads(tricept.check(c.machine, day).to_json())
    by_file = json.loads(from_file.to_json())
    for j in (by_memory, by_file):
        j.pop("machine")
    assert by_memory == by_file
    # An edited description is refused as the file would be.
    v = json.loads(m.to_json())
    v["workspace"]["radius_mm"] = 350.0
    with pytest.raises(tricept.InputError, match="workspace.radius_mm"):
        tricept.Machine.from_json(json.dumps(v))


def test_diagnosis_and_check_results_pickle_and_say_what_they_hold(tmp_path):
    d = tricept.diagnose(HIDDEN)
    back = pickle.loads(pickle.dumps(d))
    assert (back.exit_code, back.to_json(), back.report()) == (d.exit_code, d.to_json(), d.report())
    assert d.verdict == json.loads(d.to_json())["verdict"]
    assert d.causes == ["compliance"]
    assert repr(d) == f"Diagnosis(exit_code={d.exit_code}, verdict={d.verdict!r}, causes=['compliance'])"
    assert repr(back) == repr(d)
    d.write_machine(tmp_path / "live.json")
    back.write_machine(tmp_path / "copy.json")
    p = np.array([[10.0, -20.0, 760.0]])
    np.testing.assert_array_equal(
        tricept.Machine.load(tmp_path / "live.json").ik(p), tricept.Machine.load(tmp_path / "copy.json").ik(p)
    )
    c = tricept.identify(GRID)
    c.write_machine(tmp_path / "cal.json")
    truth = json.loads((ROOT / "fixtures" / "errors" / "table2.json").read_text())
    truth["dq2"] += 0.02
    (tmp_path / "slip.json").write_text(json.dumps(truth))
    day = tricept.simulate(truth=str(tmp_path / "slip.json"), poses="random:20,9", seed=4)
    r = tricept.check(tmp_path / "cal.json", day)
    assert r.exit_code == 3 and r.verdict == "changed"
    assert r.most_likely and "leg 2" in r.most_likely
    assert repr(r) == f"CheckResult(exit_code=3, verdict='changed', most_likely={r.most_likely!r})"
    back = pickle.loads(pickle.dumps(r))
    assert (back.exit_code, back.to_json(), back.report(), repr(back)) == (3, r.to_json(), r.report(), repr(r))


def test_an_effect_given_as_one_string_is_one_effect_and_simulate_revisits(cli, tmp_path):
    effect = {"effect": "leg-lead", "ppm": [50, -30, 40]}
    one = tricept.simulate(poses="random:12,2", effects=json.dumps(effect))
    assert all(np.array_equal(one[k], v) for k, v in tricept.simulate(poses="random:12,2", effects=[effect]).items())
    with pytest.raises(tricept.InputError, match="`leg-lead` names an effect"):
        tricept.simulate(effects="leg-lead")
    got = tricept.simulate(poses="random:12,2", seed=3, revisit=4)
    assert len(got["q1"]) == 16
    np.testing.assert_array_equal(got["q1"][12:], got["q1"][:4])
    out = cli("simulate", "--poses", "random:12,2", "--seed", "3", "--revisit", "4", "--out", tmp_path / "r.csv")
    assert out.returncode == 0, out.stderr
    expected = columns(tmp_path / "r.csv")
    for k in expected:
        np.testing.assert_array_equal(got[k], expected[k])


MEMORY_PROBE = r"""
import resource, numpy as np, tricept
m = tricept.Machine.paper()
n = 40_000_000
points = np.zeros((n, 3))  # 0.96 GB of address space, untouched (calloc)
pages = int(open("/proc/self/statm").read().split()[0])
in_use = pages * resource.getpagesize()
# Room for 1 GB more: the (n, 6) result (1.92 GB) does not fit.
resource.setrlimit(resource.RLIMIT_AS, (in_use + (1 << 30), resource.RLIM_INFINITY))
try:
    m.ik(points)
    print("no error")
except MemoryError as e:
    print("MemoryError:", e)
print("alive", m.ik(np.array([[0.0, 0.0, 750.0]]))[0, 0])
"""


def test_a_result_the_memory_cannot_hold_is_a_memory_error_not_an_abort():
    out = subprocess.run([sys.executable, "-c", MEMORY_PROBE], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "MemoryError: ik: points: cannot allocate 240000000 values" in out.stdout, out.stdout
    assert "alive 773.3742" in out.stdout, out.stdout
