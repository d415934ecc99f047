"""The workflows from Python equal the CLI's: identify from a path and from
arrays gives the CLI's estimates (to 1e-12 mm) and exit code, diagnose and
check give the CLI's exit codes and JSON, simulate gives the CLI's file,
report the CLI's page and verdict,
and a refused or bad request raises the documented exception."""

import json
import pathlib

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


def cli_json(cli, *args):
    out = cli(*args, "--json")
    return out.returncode, json.loads(out.stdout)


def test_identify_from_a_path_and_from_arrays_equals_the_cli(cli):
    code, expected = cli_json(cli, "identify", "--data", GRID)
    from_path = tricept.identify(GRID)
    from_arrays = tricept.identify(columns(GRID))
    for c in (from_path, from_arrays):
        assert c.exit_code == code == 0
        for name, value in expected["estimates_mm"].items():
            assert abs(c.estimates[name] - value) <= 1e-12, name
        for name, sd in expected["std_dev_mm"].items():
            if sd is None:
                assert c.sd[name] is None
            else:
                assert abs(c.sd[name] - sd) <= 1e-12, name
    got = json.loads(from_path.to_json())
    assert got == expected
    cov = from_path.covariance
    assert cov.shape == (len(from_path.names), len(from_path.names))
    sd = np.sqrt(np.diag(cov))
    for j, name in enumerate(from_path.names):
        if from_path.sd[name] is not None:
            assert abs(sd[j] - from_path.sd[name]) <= 1e-9 * max(1.0, sd[j])


def test_a_pandas_like_mapping_and_write_machine_follow_the_cli_rules(cli, tmp_path):
    c = tricept.identify(GRID)
    out = c.write_machine(tmp_path / "cal.json")
    assert pathlib.Path(out).exists()
    m = tricept.Machine.load(tmp_path / "cal.json")
    # The calibrated machine commands differently from the nominal one.
    p = [[0.0, 0.0, 750.0]]
    assert np.abs(m.ik(p)[0, :3] - tricept.Machine.paper().ik(p)[0, :3]).max() > 0.1
    # Arrays cannot be recorded as a data file: refused as input.
    with pytest.raises(tricept.InputError):
        tricept.identify(columns(GRID)).write_machine(tmp_path / "arrays.json")
    # An edited calibrated file is refused, as in the CLI.
    v = json.loads((tmp_path / "cal.json").read_text())
    v["sensors"]["length_noise_um"] *= 3
    (tmp_path / "edited.json").write_text(json.dumps(v))
    with pytest.raises(tricept.InputError, match="sensors"):
        tricept.Machine.load(tmp_path / "edited.json")


def test_an_inadequate_fit_has_the_cli_exit_code_and_is_refused_unless_forced(cli, tmp_path):
    code, _ = cli_json(cli, "identify", "--data", HIDDEN)
    c = tricept.identify(HIDDEN)
    assert c.exit_code == code == 3
    with pytest.raises(tricept.UntrustedError):
        c.write_machine(tmp_path / "no.json")
    assert not (tmp_path / "no.json").exists()
    c.write_machine(tmp_path / "forced.json", force=True)
    assert json.loads((tmp_path / "forced.json").read_text())["calibration"]["forced"] is True


def test_diagnose_and_check_equal_the_cli(cli, tmp_path):
    code, expected = cli_json(cli, "diagnose", "--data", HIDDEN)
    d = tricept.diagnose(HIDDEN)
    assert d.exit_code == code
    assert json.loads(d.to_json()) == expected
    assert expected["deploy_rule"] == "expected-error"
    code, expected = cli_json(cli, "diagnose", "--data", HIDDEN, "--deploy-rule", "confident")
    d = tricept.diagnose(HIDDEN, deploy_rule="confident")
    assert json.loads(d.to_json()) == expected
    assert expected["deploy_rule"] == "confident"
    with pytest.raises(tricept.InputError, match="expected-error"):
        tricept.diagnose(HIDDEN, deploy_rule="always")
    # A calibration, then a check of another day's campaign.
    assert cli("simulate", "--truth", "random:0.25,5", "--poses", "random:80,3", "--out", tmp_path / "cal.csv").returncode == 0
    assert cli("identify", "--data", tmp_path / "cal.csv", "--write-machine", tmp_path / "cal.json").returncode == 0
    assert cli("simulate", "--truth", "random:0.25,5", "--poses", "random:20,9", "--seed", "4", "--out", tmp_path / "day.csv").returncode == 0
    code, expected = cli_json(cli, "check", "--machine", tmp_path / "cal.json", "--data", tmp_path / "day.csv")
    r = tricept.check(tmp_path / "cal.json", tmp_path / "day.csv")
    assert r.exit_code == code == 0
    assert json.loads(r.to_json()) == expected
    from_arrays = json.loads(tricept.check(tmp_path / "cal.json", columns(tmp_path / "day.csv")).to_json())
    assert from_arrays.pop("data_file") == "<arrays>"
    expected.pop("data_file")
    assert from_arrays == expected


def test_simulate_gives_the_cli_file(cli, tmp_path):
    effect = {"effect": "leg-lead", "ppm": [50, -30, 40]}
    assert cli("simulate", "--poses", "random:30,2", "--seed", "7", "--truth-effect", json.dumps(effect), "--out", tmp_path / "s.csv").returncode == 0
    expected = columns(tmp_path / "s.csv")
    got = tricept.simulate(poses="random:30,2", seed=7, effects=[effect])
    assert list(got) == list(expected)
    for k in expected:
        np.testing.assert_array_equal(got[k], expected[k])
    with pytest.raises(tricept.InputError):
        tricept.simulate(effects=[{"effect": "nothing"}])


def test_bad_data_raise_input_error_with_the_cli_message(cli, tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("q1,q2,q3,phi,theta,s\n796.5,796.5,796.5,0.1,0.1,x\n")
    out = cli("identify", "--data", bad)
    assert out.returncode == 2
    with pytest.raises(tricept.InputError) as e:
        tricept.identify(bad)
    assert str(e.value) == out.stderr.strip().removeprefix("error: ")
    with pytest.raises(tricept.InputError):
        tricept.identify({"q1": [1.0, 2.0], "q2": [1.0]})


def test_report_writes_the_cli_page(cli, tmp_path):
    machine = tmp_path / "t2.json"
    assert cli("identify", "--data", GRID, "--write-machine", machine).returncode == 0
    out = cli("report", "--machine", machine, "--data", GRID, "--out", tmp_path / "cli.html", "--json")
    expected = json.loads(out.stdout)
    got = tricept.report(machine, tmp_path / "py.html", data=GRID)
    assert got.pop("exit_code") == out.returncode == 0
    assert got["verdict"] == expected["verdict"]
    assert (tmp_path / "py.html").read_bytes() == (tmp_path / "cli.html").read_bytes()
    with pytest.raises(tricept.InputError, match="not the campaign of this calibration"):
        tricept.report(machine, tmp_path / "x.html", data=HIDDEN)


def test_fleet_and_a_new_machine_from_its_prior_equal_the_cli(cli, tmp_path):
    # Four machines with their own errors, 40 poses each, simulated by the CLI.
    paths = []
    for i in range(1, 5):
        p = tmp_path / f"m{i}.csv"
        cli("simulate", "--truth", f"random:0.1,{i}", "--poses", f"random:40,{i}", "--seed", str(i), "--out", p)
        paths.append(p)
    code, expected = cli_json(cli, "fleet", "--data", *paths)
    batch = tricept.fleet(paths)
    assert batch.exit_code == code
    got = json.loads(batch.to_json())
    for key in ("batch_mean_mm", "batch_mean_sd_mm", "batch_spread_mm", "outliers", "held"):
        assert got[key] == expected[key], key
    assert [m["estimates_mm"] for m in got["machines"]] == [m["estimates_mm"] for m in expected["machines"]]
    assert got["solver"]["kind"] == "schur" and got["solver"]["readings"] == 4 * 40 * 3
    prior = tmp_path / "prior.json"
    batch.write_prior(prior)
    new = tmp_path / "new.csv"
    cli("simulate", "--truth", "random:0.1,9", "--poses", "random:12,9", "--seed", "9", "--out", new)
    code, expected = cli_json(cli, "identify", "--data", new, "--prior", prior)
    c = tricept.identify(new, prior=prior)
    assert c.exit_code == code
    assert json.loads(c.to_json())["estimates_mm"] == expected["estimates_mm"]
    assert json.loads(c.to_json())["prior"]["file"] == str(prior)
    # Two campaigns of one machine, pooled as --data twice.
    again = tmp_path / "again.csv"
    cli("simulate", "--truth", "random:0.1,9", "--poses", "random:40,10", "--seed", "10", "--out", again)
    code, expected = cli_json(cli, "identify", "--data", new, "--data", again)
    pooled = tricept.identify([new, again])
    assert pooled.exit_code == code
    assert [x["data_file"] for x in json.loads(pooled.to_json())["campaigns"]] == [str(new), str(again)]
    with pytest.raises(tricept.InputError):
        tricept.fleet(paths[0])
