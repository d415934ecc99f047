//! What the verbs rely on is sealed and bounded.
//!
//! What `tricept check` judges by is sealed: a calibrated file whose
//! standard deviations, sensor noise, correlations, offsets or
//! temperature were edited after the calibration is refused (exit 2,
//! naming the field) by every verb that loads it, so an inflated
//! `std_dev_mm` or a quieter `sensors` noise can no longer hide a real
//! 20 um slip from the check; the file as written loads everywhere.
//! Every JSON input has a size bound: a device or a runaway file is
//! refused with exit 2 after 64 MiB instead of exhausting the memory.

use std::process::Command;

use crate::support::{calibrated_machine, fresh_workdir, moved_truth, ok, run_in as tricept};

/// A work directory of this module's test `name`, emptied first.
fn workdir(name: &str) -> std::path::PathBuf {
    fresh_workdir(&format!("relied-on-{name}"))
}

#[test]
fn an_edited_judged_field_is_refused_by_name_and_cannot_hide_a_slip() {
    let dir = workdir("sealed");
    let d = dir.as_path();
    calibrated_machine(d);
    // The day's campaign: leg 2 slipped by 20 um.
    moved_truth(d, &[("dq2", 0.020)], "slipped.json");
    ok(
        d,
        &[
            "simulate",
            "--truth",
            "slipped.json",
            "--poses",
            "random:20,9",
            "--seed",
            "4",
            "--out",
            "day.csv",
        ],
    );
    let check = |machine: &str| tricept(d, &["check", "--machine", machine, "--data", "day.csv"]);
    // The file as written: the slip is seen.
    assert_eq!(check("cal.json").status.code(), Some(3));

    let original: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("cal.json")).unwrap()).unwrap();
    type Edit = fn(&mut serde_json::Value);
    let edits: [(&str, &str, Edit); 6] = [
        ("std-dev", "`calibration.std_dev_mm.dq1`", |v| {
            let sd = v["calibration"]["std_dev_mm"].as_object_mut().unwrap();
            for x in sd.values_mut() {
                if let Some(s) = x.as_f64() {
                    *x = (s * 100.0).into();
                }
            }
        }),
        (
            "noise",
            "`sensors.angle_noise_arcsec`, `sensors.length_noise_um`",
            |v| {
                v["sensors"]["angle_noise_arcsec"] = 8.0.into();
                v["sensors"]["length_noise_um"] = 5.0.into();
            },
        ),
        ("correlations", "`calibration.correlations.matrix`", |v| {
            v["calibration"]["correlations"]["matrix"][0][1] = 0.0.into();
        }),
        ("offsets", "`calibration.sensor_offsets.s_mm`", |v| {
            let s = v["calibration"]["sensor_offsets"]["s_mm"].as_f64().unwrap();
            v["calibration"]["sensor_offsets"]["s_mm"] = (s + 0.02).into();
        }),
        ("temperature", "`calibration.temperature_c`", |v| {
            v["calibration"]["temperature_c"] = 24.0.into();
        }),
        ("seal-removed", "has no `seal`", |v| {
            v["calibration"].as_object_mut().unwrap().remove("seal");
        }),
    ];
    let mut failures = Vec::new();
    for (case, needle, edit) in edits {
        let mut v = original.clone();
        edit(&mut v);
        let file = format!("edited-{case}.json");
        std::fs::write(dir.join(&file), serde_json::to_string_pretty(&v).unwrap()).unwrap();
        for verb in [
            vec!["check", "--machine", &file, "--data", "day.csv"],
            vec!["ik", "0", "0", "750", "--machine", &file],
        ] {
            let out = tricept(d, &verb);
            let err = String::from_utf8_lossy(&out.stderr).into_owned();
            if out.status.code() != Some(2) || !err.contains(needle) || !err.contains(&file) {
                failures.push(format!(
                    "{case} ({}): {:?} {err}",
                    verb[0],
                    out.status.code()
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The file written again from a loaded calibrated machine keeps a
    // valid seal (a recalibration writes its own).
    ok(
        d,
        &[
            "identify",
            "--data",
            "cal.csv",
            "--machine",
            "cal.json",
            "--write-machine",
            "again.json",
        ],
    );
    ok(d, &["ik", "0", "0", "750", "--machine", "again.json"]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn every_json_input_is_bounded() {
    let dir = workdir("bounded");
    let d = dir.as_path();
    let out = tricept(d, &["simulate", "--poses", "random:40,3", "--out", "d.csv"]);
    assert_eq!(out.status.code(), Some(0));
    let out = tricept(
        d,
        &["identify", "--data", "d.csv", "--write-machine", "m.json"],
    );
    assert_eq!(out.status.code(), Some(0));
    let z = "/dev/zero";
    // A history is appended to: a device is refused as not a regular file
    // before it is read.
    let out = tricept(
        d,
        &[
            "check",
            "--machine",
            "m.json",
            "--data",
            "d.csv",
            "--history",
            z,
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--history /dev/zero: is a character device"),
        "{err}"
    );
    let cases: [(&str, Vec<&str>); 6] = [
        ("machine", vec!["ik", "0", "0", "750", "--machine", z]),
        ("truth", vec!["simulate", "--truth", z, "--out", "t.csv"]),
        (
            "truth-effect",
            vec!["simulate", "--truth-effect", "@/dev/zero", "--out", "t.csv"],
        ),
        (
            "plausibility",
            vec!["diagnose", "--data", "d.csv", "--plausibility", z],
        ),
        (
            "features",
            vec![
                "identify",
                "--data",
                "d.csv",
                "--touch",
                "d.csv",
                "--features",
                z,
            ],
        ),
        (
            "fused-plausibility",
            vec![
                "identify",
                "--data",
                "d.csv",
                "--head",
                "none",
                "--plausibility",
                z,
            ],
        ),
    ];
    let mut failures = Vec::new();
    for (case, args) in cases {
        let out = tricept(d, &args);
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        if out.status.code() != Some(2)
            || !err.contains("64 MiB")
            || err.trim().lines().count() != 1
        {
            failures.push(format!("{case}: {:?} {err}", out.status.code()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn help_and_version_to_a_full_disk_fail() {
    let dir = workdir("full");
    for args in [
        vec!["--help"],
        vec!["--version"],
        vec!["identify", "--help"],
    ] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_tricept"))
            .args(&args)
            .current_dir(&dir)
            .stdout(full)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("incomplete"),
            "{args:?}"
        );
        // To a pipe they still succeed.
        assert_eq!(tricept(&dir, &args).status.code(), Some(0), "{args:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The fixture of a campaign with a hidden effect the diagnosis names.
fn hidden_effect() -> String {
    format!(
        "{}/../../fixtures/data/diagnose-hidden-effect.csv",
        env!("CARGO_MANIFEST_DIR")
    )
}

#[test]
fn plots_never_overwrite_an_input_or_the_history() {
    let dir = workdir("plots");
    let d = dir.as_path();
    let fixture = hidden_effect();
    // The plots of this file's diagnosis, by name.
    let out = tricept(d, &["diagnose", "--data", &fixture, "--plots", "p"]);
    assert_eq!(out.status.code(), Some(0));
    let plot = std::fs::read_dir(dir.join("p"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .file_name();
    let plot = plot.to_str().unwrap();
    // The data file where the plot would go: refused, the data intact.
    std::fs::create_dir_all(dir.join("q")).unwrap();
    let data = std::fs::read(&fixture).unwrap();
    std::fs::write(dir.join("q").join(plot), &data).unwrap();
    let as_input = format!("q/{plot}");
    let out = tricept(d, &["diagnose", "--data", &as_input, "--plots", "q"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("the input --data"));
    assert_eq!(std::fs::read(dir.join("q").join(plot)).unwrap(), data);
    // check --plot: a history file named as a trend plot is not overwritten.
    calibrated_machine(d);
    std::fs::create_dir_all(dir.join("t")).unwrap();
    for seed in ["4", "5", "6"] {
        ok(
            d,
            &[
                "simulate",
                "--truth",
                "random:0.25,5",
                "--poses",
                "random:20,9",
                "--seed",
                seed,
                "--out",
                "day.csv",
            ],
        );
        ok(
            d,
            &[
                "check",
                "--machine",
                "cal.json",
                "--data",
                "day.csv",
                "--history",
                "t/check-dq1.svg",
            ],
        );
    }
    let history = std::fs::read(dir.join("t/check-dq1.svg")).unwrap();
    let out = tricept(
        d,
        &[
            "check",
            "--machine",
            "cal.json",
            "--data",
            "day.csv",
            "--history",
            "t/check-dq1.svg",
            "--plot",
            "t",
        ],
    );
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("the output --history"));
    // The refusal comes before the check: nothing is appended.
    let after = std::fs::read(dir.join("t/check-dq1.svg")).unwrap();
    assert_eq!(after, history);
    std::fs::remove_dir_all(&dir).ok();
}

/// `diagnose --json` says which deploy rule judged the terms (the default
/// `expected-error`, or `--deploy-rule confident`), and states every
/// model term's expected errors with and without it, and why a term is
/// kept back (`null` for a deployed one).
#[test]
fn the_deploy_rule_and_the_expected_errors_are_in_the_json() {
    let dir = workdir("deploy-rule");
    let d = dir.as_path();
    let fixture = hidden_effect();
    for (extra, name) in [
        (&[][..], "expected-error"),
        (&["--deploy-rule", "confident"][..], "confident"),
        (&["--deploy-rule", "expected-error"][..], "expected-error"),
    ] {
        let mut args = vec!["diagnose", "--json", "--data", &fixture];
        args.extend_from_slice(extra);
        let out = tricept(d, &args);
        assert_eq!(out.status.code(), Some(0), "{args:?}");
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(json["deploy_rule"], name);
        let terms = json["model_terms"].as_array().expect("model_terms");
        assert!(!terms.is_empty());
        for t in terms {
            let (with, without) = (
                t["expected_rms_with_mm"].as_f64(),
                t["expected_rms_without_mm"].as_f64(),
            );
            assert!(
                with.is_some_and(|w| w >= 0.0) && without.is_some_and(|w| w >= 0.0),
                "{t}"
            );
            assert_eq!(t["deployed"], t["kept_back_because"].is_null(), "{t}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
