//! The fused identification from the command line, end to end: plan
//! tracker points, simulate them, identify module and head, write the
//! calibrated machine, and check that `tool-ik` on it puts the fused
//! model's tool tip where it is asked to be; an unexplained source ends
//! with exit code 3 and says so.

use std::path::Path;

use nalgebra::Vector3;
use tricept_data::external::ExternalPose;
use tricept_engine::fusion::FusedModel;
use tricept_kinematics::Machine;
use tricept_model::{ParameterSet, head_errors::Effector};

use crate::support::{ok, run_in as tricept, workdir};

/// In `dir`: 20 planned tracker poses (`points.csv`), then the simulated
/// machine's internal data (`internal.csv`, head errors `random:1,5`) and
/// its tracker points at those poses (`tracker.csv`).
fn simulate_tracker_campaign(dir: &Path) {
    plan_and_simulate(dir, "20", &[]);
}

#[test]
fn the_calibrated_machine_file_carries_the_head_and_tool_ik_uses_it() {
    let dir = workdir("fusion-deploy");
    simulate_tracker_campaign(&dir);
    let json = ok(
        &dir,
        &[
            "identify",
            "--data",
            "internal.csv",
            "--tracker",
            "tracker.csv",
            "--tracker-target",
            "tip",
            "--write-machine",
            "calibrated.json",
            "--json",
        ],
    );
    let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
    assert_eq!(v["deployed"]["written"], "calibrated.json");
    assert_eq!(v["rank"], 25);
    let m = Machine::paper();
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap();
    let estimate: Vec<f64> = model
        .names()
        .iter()
        .map(|n| v[n].as_f64().unwrap())
        .collect();
    let text = std::fs::read_to_string(dir.join("calibrated.json")).unwrap();
    assert!(text.contains("angle_offsets_rad") && text.contains("held at nominal"));
    // The accuracy block: at the tool tip, in the JSON and in the file.
    let a = &v["accuracy"];
    assert_eq!(a["point"], "tool tip");
    let (rms, upper) = (
        a["rms_mm"].as_f64().unwrap(),
        a["upper_mm"].as_f64().unwrap(),
    );
    assert!(rms > 0.0 && upper >= rms, "{a}");
    let file: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(
        file["calibration"]["accuracy"]["upper_mm"].as_f64(),
        Some(upper)
    );
    // tool-ik on the written machine: the fused model's tool tip lands on
    // the target to 1e-9 mm.
    for j in 0..12 {
        let a = j as f64 * 0.7;
        let tip = Vector3::new(200.0 * a.cos(), 150.0 * a.sin(), 1080.0 + 5.0 * j as f64);
        let axis = Vector3::new(0.3 * (2.0 * a).cos(), 0.3 * (2.0 * a).sin(), 1.0);
        let args: Vec<String> = [tip.x, tip.y, tip.z, axis.x, axis.y, axis.z]
            .iter()
            .map(|x| x.to_string())
            .collect();
        let mut call = vec!["tool-ik", "--machine", "calibrated.json", "--json"];
        call.extend(args.iter().map(String::as_str));
        let r: serde_json::Value = serde_json::from_slice(&ok(&dir, &call)).unwrap();
        let pose = ExternalPose {
            commands_mm: ["q1", "q2", "q3"].map(|k| r[k].as_f64().unwrap()),
            head_rad: ["h1", "h2"].map(|k| r[k].as_f64().unwrap()),
        };
        let (reached, _) = model
            .spindle_point(&estimate, &pose, &Effector::default())
            .unwrap();
        assert!(
            (reached - tip).norm() < 1e-9,
            "{j}: {:e} mm",
            (reached - tip).norm()
        );
    }
    // The calibration record: the fused fit's provenance, every external
    // file with its hash, the nominal machine of the rank rule.
    let file: serde_json::Value = serde_json::from_str(&text).unwrap();
    let record = &file["calibration"];
    assert_eq!(record["method"], "identify (fused)");
    assert_eq!(record["data_file"], "internal.csv");
    assert_eq!(record["external_sources"][0]["kind"], "tracker");
    assert_eq!(record["external_sources"][0]["file"], "tracker.csv");
    assert_eq!(record["external_sources"][0]["records"], 20);
    assert_eq!(
        record["external_sources"][0]["sha256"]
            .as_str()
            .unwrap()
            .len(),
        64
    );
    assert!(record["estimates_mm"]["h1_zero_rad"].is_number());
    // The station's frame is kept: the simulated tracker's default frame
    // maps the base frame by the rotation vector (0.1, 0.2, 0.3) rad and the
    // translation (1500, -800, 200) mm.
    let nuisance = &record["external_sources"][0]["nuisance"];
    for (name, expected) in [
        ("tracker.s1.rx_rad", 0.1),
        ("tracker.s1.ry_rad", 0.2),
        ("tracker.s1.rz_rad", 0.3),
        ("tracker.s1.tx_mm", 1500.0),
        ("tracker.s1.ty_mm", -800.0),
        ("tracker.s1.tz_mm", 200.0),
    ] {
        let (v, sd) = (
            nuisance[name]["value"].as_f64().unwrap(),
            nuisance[name]["std_dev"].as_f64().unwrap(),
        );
        assert!(
            (v - expected).abs() < 5.0 * sd,
            "{name} = {v} +- {sd}, expected {expected}"
        );
    }
    assert_eq!(record["external_sources"][0]["checkable"], true);
    // The verdict fields of `identify`, and the fused fit's own.
    for key in [
        "converged",
        "adequate",
        "consistent_with_machine",
        "checkable",
        "plausible",
    ] {
        assert_eq!(v[key], true, "{key}");
    }
    assert!(v["chi_square_p_value"].as_f64().unwrap() > 1e-3);
    assert!(v["sources"][1]["redundancy"].as_f64().unwrap() >= 6.0);
    assert!(v["visibility"]["tool_axis"]["rms_arcsec"].is_number());
    assert!(file["name"].as_str().unwrap().contains("calibrated"));
    // Identifying the internal data again against it keeps the rank rule
    // of the nominal machine: dyA3 stays held.
    let again: serde_json::Value = serde_json::from_slice(&ok(
        &dir,
        &[
            "identify",
            "--data",
            "internal.csv",
            "--machine",
            "calibrated.json",
            "--json",
        ],
    ))
    .unwrap();
    assert_eq!(again["fixed"], serde_json::json!(["dyA3"]));
    // A nominal file is printed as it always was: no head angle offsets.
    let nominal = String::from_utf8(ok(&dir, &["machine"])).unwrap();
    assert!(!nominal.contains("angle_offsets_rad"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_unexplained_source_ends_with_exit_code_3_and_a_warning() {
    let dir = workdir("fusion-untrusted");
    plan_tracker(&dir, "12");
    // Leg leads of a few hundred ppm: the geometric model cannot explain
    // the readings.
    ok(
        &dir,
        &[
            "simulate",
            "--out",
            "internal.csv",
            "--effect",
            r#"{"effect":"leg-lead","ppm":[300,-200,250]}"#,
            "--tracker-out",
            "tracker.csv",
            "--tracker-poses",
            "points.csv",
        ],
    );
    let out = tricept(
        &dir,
        &[
            "identify",
            "--data",
            "internal.csv",
            "--tracker",
            "tracker.csv",
            "--tracker-target",
            "tip",
            "--json",
        ],
    );
    assert_eq!(
        out.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let warnings = v["warnings"].as_array().unwrap();
    assert!(
        warnings
            .iter()
            .any(|w| w.as_str().unwrap().contains("does not explain"))
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("run `tricept diagnose`"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn fusing_against_a_calibrated_machine_keeps_the_nominal_rank_rule() {
    // A machine calibrated by `identify`, then re-calibrated with a tracker:
    // on the calibrated geometry dyA3 is weakly visible; the fused fit must
    // hold it as `identify` does, not chase it.
    let dir = workdir("fusion-recalibrate");
    simulate_tracker_campaign(&dir);
    ok(
        &dir,
        &[
            "identify",
            "--data",
            "internal.csv",
            "--write-machine",
            "calibrated.json",
        ],
    );
    let fused = |machine: Option<&str>| -> serde_json::Value {
        let mut args = vec![
            "identify",
            "--data",
            "internal.csv",
            "--tracker",
            "tracker.csv",
            "--tracker-target",
            "tip",
            "--json",
        ];
        if let Some(m) = machine {
            args.extend(["--machine", m]);
        }
        serde_json::from_slice(&ok(&dir, &args)).unwrap()
    };
    let (nominal, calibrated) = (fused(None), fused(Some("calibrated.json")));
    assert_eq!(calibrated["converged"], true);
    assert_eq!(calibrated["rank"], nominal["rank"]);
    assert_eq!(calibrated["fixed"], nominal["fixed"]);
    assert!(calibrated["fixed"].to_string().contains("dyA3"));
    std::fs::remove_dir_all(&dir).ok();
}

/// `points.csv`: `k` planned tracker points, target at the tip.
fn plan_tracker(dir: &Path, k: &str) {
    ok(
        dir,
        &[
            "plan",
            "--instrument",
            "tracker",
            "--tracker-target",
            "tip",
            "--k",
            k,
            "--random-baseline",
            "0",
            "--passes",
            "1",
            "--out",
            "points.csv",
        ],
    );
}

/// `points.csv` (`k` planned points), then the simulated machine's
/// internal data (`internal.csv`, head errors `random:1,5`) and its tracker
/// points there (`tracker.csv`), with `simulate_extra` arguments.
fn plan_and_simulate(dir: &Path, k: &str, simulate_extra: &[&str]) {
    plan_tracker(dir, k);
    let mut args = vec![
        "simulate",
        "--head-errors",
        "random:1,5",
        "--out",
        "internal.csv",
        "--tracker-out",
        "tracker.csv",
        "--tracker-poses",
        "points.csv",
    ];
    args.extend(simulate_extra);
    ok(dir, &args);
}

#[test]
fn five_tracker_points_cannot_be_checked_exit_3_and_the_file_is_refused_with_its_report() {
    let dir = workdir("fusion-saturated");
    plan_and_simulate(&dir, "5", &[]);
    let fused = [
        "identify",
        "--data",
        "internal.csv",
        "--tracker",
        "tracker.csv",
        "--tracker-target",
        "tip",
    ];
    let json = tricept(&dir, &[&fused[..], &["--json"]].concat());
    assert_eq!(json.status.code(), Some(3));
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let tracker = &v["sources"][1];
    assert_eq!(tracker["checkable"], false);
    assert!(tracker["redundancy"].as_f64().unwrap() < 1.0, "{tracker}");
    let more = tracker["more_records"].as_u64().unwrap();
    assert!(more >= 1);
    assert_eq!(
        (v["checkable"].clone(), v["adequate"].clone()),
        (false.into(), false.into())
    );
    let stderr = String::from_utf8_lossy(&json.stderr);
    assert!(
        stderr.contains(&format!("at least {more} more points make it checkable")),
        "{stderr}"
    );
    // --write-machine: refused, after the report and the warnings.
    let out = tricept(&dir, &[&fused[..], &["--write-machine", "m.json"]].concat());
    assert_eq!(out.status.code(), Some(3));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stdout.contains("fused identification") && stdout.contains("NOT checkable"));
    assert!(
        stderr.contains("warning: tracker (tracker.csv) cannot be checked"),
        "{stderr}"
    );
    let last = stderr.lines().last().unwrap();
    assert!(
        last.contains("--write-machine m.json: not written")
            && last.contains(&format!(
                "tracker cannot be checked: at least {more} more records"
            )),
        "{last}"
    );
    assert!(!dir.join("m.json").exists());
    // --force writes it, marked forced.
    let out = tricept(
        &dir,
        &[&fused[..], &["--write-machine", "m.json", "--force"]].concat(),
    );
    assert_eq!(out.status.code(), Some(3));
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("m.json")).unwrap()).unwrap();
    assert_eq!(file["calibration"]["forced"], true);
    assert_eq!(
        file["calibration"]["external_sources"][0]["checkable"],
        false
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_target_beyond_the_tip_stated_as_tip_is_implausible_and_the_cause_is_named() {
    let dir = workdir("fusion-implausible");
    // The simulated target sits 20 mm beyond the tip along the tool.
    plan_and_simulate(&dir, "20", &["--tracker-target-mm", "0,0,20"]);
    let fused = |target: &str| {
        tricept(
            &dir,
            &[
                "identify",
                "--data",
                "internal.csv",
                "--tracker",
                "tracker.csv",
                "--tracker-target",
                target,
                "--write-machine",
                "m.json",
            ],
        )
    };
    let out = fused("tip");
    assert_eq!(out.status.code(), Some(3));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("tool_length_mm = ") && stderr.contains("far outside its plausible range"),
        "{stderr}"
    );
    assert!(
        stderr.contains("likely cause (tested)")
            && stderr.contains("not where tracker_target says")
    );
    assert!(stderr.contains("not written") && !dir.join("m.json").exists());
    // The sign wrong: named as such.
    let out = fused("0,0,-20");
    assert_eq!(out.status.code(), Some(3));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("the target offset's sign is wrong"),
        "{stderr}"
    );
    // Stated as it is: plausible, written.
    let out = fused("0,0,20");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.join("m.json").exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn touch_offs_end_to_end_plan_simulate_identify() {
    let dir = workdir("fusion-touch");
    let plan = ok(
        &dir,
        &[
            "plan",
            "--instrument",
            "touch",
            "--k",
            "30",
            "--random-baseline",
            "0",
            "--passes",
            "1",
            "--out",
            "touches.csv",
            "--json",
        ],
    );
    let p: serde_json::Value = serde_json::from_slice(&plan).unwrap();
    assert_eq!(p["rows"][0]["checkable"], true, "{p}");
    ok(
        &dir,
        &[
            "simulate",
            "--head-errors",
            "random:1,5",
            "--out",
            "internal.csv",
            "--touch-out",
            "touch.csv",
            "--features-out",
            "features.json",
            "--touch-poses",
            "touches.csv",
            "--touch-stylus-error-um",
            "1.5",
        ],
    );
    let v: serde_json::Value = serde_json::from_slice(&ok(
        &dir,
        &[
            "identify",
            "--data",
            "internal.csv",
            "--touch",
            "touch.csv",
            "--features",
            "features.json",
            "--write-machine",
            "m.json",
            "--json",
        ],
    ))
    .unwrap();
    // The simulated sphere sits at the default (0, 0, 1150) mm, the stylus
    // 1.5 um larger than its nominal 1 mm.
    let touch = &v["sources"][1];
    assert_eq!(touch["kind"], "touch");
    for (name, expected) in [
        ("touch.f1.centre_x_mm", 0.0),
        ("touch.f1.centre_y_mm", 0.0),
        ("touch.f1.centre_z_mm", 1150.0),
    ] {
        let (x, sd) = (
            touch["nuisance"][name].as_f64().unwrap(),
            touch["nuisance_std_dev"][name].as_f64().unwrap(),
        );
        // The machine's own errors move where it finds the sphere: a few
        // tenths of a mm (the tool tip after touch-off is what matters).
        assert!((x - expected).abs() < 2.0, "{name} = {x} +- {sd}");
    }
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("m.json")).unwrap()).unwrap();
    let record = &file["calibration"]["external_sources"][0];
    assert_eq!(record["kind"], "touch");
    assert!(record["nuisance"]["touch.stylus_radius_mm"]["value"].is_number());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_old_noise_flag_of_plan_still_works() {
    let dir = workdir("fusion-alias");
    let run = |flag: &str| -> serde_json::Value {
        serde_json::from_slice(&ok(
            &dir,
            &[
                "plan",
                "--instrument",
                "ballbar",
                "--k",
                "30",
                "--random-baseline",
                "0",
                "--passes",
                "1",
                "--json",
                flag,
                "2",
            ],
        ))
        .unwrap()
    };
    assert_eq!(run("--sigma-um")["rows"], run("--ballbar-sigma-um")["rows"]);
    std::fs::remove_dir_all(&dir).ok();
}
