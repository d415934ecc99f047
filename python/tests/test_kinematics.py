"""Batch kinematics from numpy equal the CLI's `--input` batch to 1e-9 mm,
refuse bad input with the CLI's kind of message, and release the GIL."""

import threading
import time

import numpy as np
import pytest

import tricept


def csv_rows(text):
    lines = [l for l in text.splitlines() if l and not l.startswith("#")]
    header = lines[0].split(",")
    rows = np.array([[float(v) for v in l.split(",")] for l in lines[1:]])
    return header, rows


def workspace_points(n, seed):
    rng = np.random.default_rng(seed)
    r = 300.0 * np.sqrt(rng.uniform(size=n))
    a = rng.uniform(0, 2 * np.pi, size=n)
    z = rng.uniform(650.0, 850.0, size=n)
    return np.column_stack([r * np.cos(a), r * np.sin(a), z])


def test_ik_and_fk_equal_the_cli_batch(cli, tmp_path):
    m = tricept.Machine.paper()
    pts = workspace_points(200, 1)
    (tmp_path / "p.csv").write_text(
        "x,y,z\n" + "\n".join(",".join(repr(float(v)) for v in p) for p in pts) + "\n"
    )
    out = cli("ik", "--input", tmp_path / "p.csv")
    assert out.returncode == 0, out.stderr
    header, rows = csv_rows(out.stdout)
    q = m.ik(pts)
    assert q.shape == (200, 6)
    for j, key in enumerate(["q1", "q2", "q3", "phi", "theta", "q4"]):
        np.testing.assert_allclose(q[:, j], rows[:, header.index(key)], rtol=0, atol=1e-9)
    (tmp_path / "q.csv").write_text(
        "q1,q2,q3\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in q[:, :3]) + "\n"
    )
    out = cli("fk", "--input", tmp_path / "q.csv")
    assert out.returncode == 0, out.stderr
    header, rows = csv_rows(out.stdout)
    x = m.fk(q[:, :3])
    assert x.shape == (200, 8)
    for j, key in enumerate(["x", "y", "z", "phi", "theta", "q4"]):
        np.testing.assert_allclose(x[:, j], rows[:, header.index(key)], rtol=0, atol=1e-9)
    # And FK undoes IK (independent of the CLI).
    np.testing.assert_allclose(x[:, :3], pts, rtol=0, atol=1e-9)


def test_tool_ik_equals_the_cli_batch(cli, tmp_path):
    m = tricept.Machine.paper()
    tips = workspace_points(50, 2) + np.array([0.0, 0.0, 300.0])
    axes = np.tile([0.1, -0.05, 1.0], (50, 1))
    (tmp_path / "t.csv").write_text(
        "x,y,z,ax,ay,az\n"
        + "\n".join(",".join(repr(float(v)) for v in [*t, *a]) for t, a in zip(tips, axes))
        + "\n"
    )
    out = cli("tool-ik", "--input", tmp_path / "t.csv")
    assert out.returncode == 0, out.stderr
    header, _ = csv_rows(out.stdout.replace("true", "1").replace("false", "0"))
    _, rows = csv_rows(out.stdout.replace("true", "1").replace("false", "0"))
    got = m.tool_ik(tips, axes)
    for j, key in enumerate(["q1", "q2", "q3", "phi", "theta", "q4", "h1", "h2", "head_singular"]):
        np.testing.assert_allclose(got[:, j], rows[:, header.index(key)], rtol=0, atol=1e-9)


def test_bad_input_raises_input_error_naming_the_row():
    m = tricept.Machine.paper()
    assert issubclass(tricept.InputError, ValueError)
    with pytest.raises(tricept.InputError, match="expected an \\(n, 3\\) array"):
        m.ik(np.zeros((4, 2)))
    far = workspace_points(5, 3)
    far[3] = [5000.0, 0.0, 750.0]
    with pytest.raises(tricept.InputError, match="row 3"):
        m.ik(far)
    with pytest.raises(tricept.InputError, match="not an array of numbers"):
        m.ik([["a", "b", "c"]])


def test_a_machine_file_loads_and_a_missing_one_is_file_not_found(cli, tmp_path):
    out = cli("machine", "--json")
    assert out.returncode == 0
    (tmp_path / "m.json").write_text(out.stdout)
    m = tricept.Machine.load(tmp_path / "m.json")
    assert m.source.endswith("m.json")
    np.testing.assert_allclose(
        m.ik([[0.0, 0.0, 750.0]]), tricept.Machine.paper().ik([[0.0, 0.0, 750.0]]), atol=1e-12
    )
    with pytest.raises(FileNotFoundError, match="nothing.json"):
        tricept.Machine.load(tmp_path / "nothing.json")


def test_a_long_call_releases_the_gil():
    """While one thread solves a large batch, another thread runs Python
    code: with the GIL held it could not tick until the batch ended."""
    m = tricept.Machine.paper()
    pts = np.tile(workspace_points(1000, 4), (3000, 1))
    ticks = []
    done = threading.Event()

    def ticker():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=ticker)
    start = time.perf_counter()
    result = {}

    def work():
        result["q"] = m.ik(pts)
        result["end"] = time.perf_counter()

    w = threading.Thread(target=work)
    t.start()
    time.sleep(0.01)
    w.start()
    w.join()
    done.set()
    t.join()
    during = [x for x in ticks if start + 0.02 < x < result["end"]]
    assert result["end"] - start > 0.1, "the batch is too short to tell"
    assert len(during) >= 5, f"{len(during)} ticks while the batch ran"
