//! The door's first example (crates/ident/src/first_example.md) run on
//! machine files the CLI wrote: `kinematics::Machine` commands a deployed
//! machine (leg leads from a diagnosis) and a calibration exactly as
//! `tricept ik --machine` does, and the geometric path it keeps apart is
//! off by the leads the simulator put in.

use std::path::Path;

use crate::support::{fixture, fresh_workdir, run, stderr};
use tricept_ident::calibrate::{CalibrateRequest, calibrate};
use tricept_ident::kinematics::{Machine, Vector3};

/// The simulated leg leads, ppm (the simulator's input).
const LEAD_PPM: [f64; 3] = [60.0, -40.0, 60.0];

/// Targets at the centre and off it, mm.
const TARGETS: [[f64; 3]; 3] = [
    [0.0, 0.0, 750.0],
    [150.0, -80.0, 720.0],
    [-120.0, 60.0, 800.0],
];

/// `tricept ik --machine FILE X Y Z --json`'s leg commands.
fn cli_ik(file: &Path, t: [f64; 3]) -> [f64; 3] {
    let (x, y, z) = (t[0].to_string(), t[1].to_string(), t[2].to_string());
    let out = run(&[
        "ik",
        "--machine",
        file.to_str().unwrap(),
        "--json",
        "--",
        &x,
        &y,
        &z,
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    ["q1", "q2", "q3"].map(|k| v[k].as_f64().unwrap())
}

fn max_diff(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max)
}

/// The first example's calls (`Machine::load(file)?.inverse(&target)?`)
/// against the CLI, and the geometric path against the leads.
fn commands_as_the_cli(file: &Path) {
    let machine = Machine::load(file).unwrap();
    assert!(machine.has_leg_effects());
    let lead = machine.leg_effects().lead_ppm;
    for t in TARGETS {
        let target = Vector3::new(t[0], t[1], t[2]);
        let q = machine.inverse(&target).unwrap().legs_mm;
        let cli = cli_ik(file, t);
        assert!(max_diff(q, cli) < 1e-9, "{t:?}: door {q:?}, cli {cli:?}");
        // Commanding the geometry alone misses the leads: the leg grows by
        // lead 1e-6 q, so its command is short of the geometric one by
        // that much (to first order in the lead).
        let geometric = machine.geometry().inverse(&target).unwrap().legs_mm;
        for i in 0..3 {
            let expected_mm = geometric[i] * lead[i] * 1e-6;
            let missed_mm = geometric[i] - q[i];
            assert!(
                (missed_mm - expected_mm).abs() < 1e-3 * expected_mm.abs() + 1e-9,
                "leg {}: {missed_mm} mm missed, {expected_mm} expected",
                i + 1
            );
            assert!(missed_mm.abs() > 0.025, "leg {}: {missed_mm}", i + 1);
        }
    }
}

#[test]
fn the_first_example_commands_a_deployed_machine_as_tricept_ik_does() {
    let dir = fresh_workdir("door-deployed");
    let data = dir.join("lead.csv");
    let effect = format!(
        r#"{{"effect":"leg-lead","ppm":[{},{},{}]}}"#,
        LEAD_PPM[0], LEAD_PPM[1], LEAD_PPM[2]
    );
    let out = run(&[
        "simulate",
        "--out",
        data.to_str().unwrap(),
        "--truth",
        "table2",
        "--truth-effect",
        &effect,
        "--seed",
        "11",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let deployed = dir.join("deployed.json");
    let out = run(&[
        "diagnose",
        "--data",
        data.to_str().unwrap(),
        "--write-machine",
        deployed.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    // The diagnosis deployed the simulated leads (within its noise).
    let lead = Machine::load(&deployed).unwrap().leg_effects().lead_ppm;
    for i in 0..3 {
        assert!((lead[i] - LEAD_PPM[i]).abs() < 10.0, "{lead:?}");
    }
    commands_as_the_cli(&deployed);
    // The example's own file, kept in fixtures/compat.
    commands_as_the_cli(Path::new(&fixture("compat/machine-deployed.json")));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_calibrations_identified_machine_commands_as_its_written_file() {
    let dir = fresh_workdir("door-calibrated");
    let data = fixture("data/table2-grid-seed1.csv");
    let file = dir.join("calibrated.json");
    let out = run(&[
        "identify",
        "--data",
        &data,
        "--write-machine",
        file.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let calibration = calibrate(CalibrateRequest::new(data.as_str())).unwrap();
    let identified = calibration.identified();
    for t in TARGETS {
        let q = identified
            .inverse(&Vector3::new(t[0], t[1], t[2]))
            .unwrap()
            .legs_mm;
        let cli = cli_ik(&file, t);
        assert!(max_diff(q, cli) < 1e-9, "{t:?}: door {q:?}, cli {cli:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
