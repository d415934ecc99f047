//! The machine file records its calibration and round-trips: a forced
//! machine is marked, the file loads everywhere, a recalibration keeps a
//! record the file is checked against.

use super::*;

#[test]
fn a_forced_machine_is_marked_and_warned_about_when_loaded() {
    let dir = workdir("trust-forced");
    let good = std::fs::read_to_string(fixture("data/table2-grid-seed1.csv")).unwrap();
    let bad = dir.join("swap.csv");
    rewrite(
        &good,
        &bad,
        |h| {
            let (i, j) = (col(h, "phi"), col(h, "theta"));
            h.swap(i, j);
        },
        |_, _, _| {},
    );
    let m = dir.join("forced.json");
    let (code, _, _) = identify(&bad, &["--force"], &m);
    assert_ne!(code, 0);
    let d: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&m).unwrap()).unwrap();
    assert_eq!(d["calibration"]["forced"], true);
    assert!(d["name"].as_str().unwrap().contains("FORCED"));
    let out = run(&["machine", "--machine", m.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("written although it is not to be trusted (forced)"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_calibrated_machine_file_is_complete_loads_everywhere_and_round_trips() {
    let dir = workdir("trust-roundtrip");
    let data = fixture("data/table2-grid-seed1.csv");
    let m1 = dir.join("calibrated.json");
    let (code, id1, _) = identify(Path::new(&data), &[], &m1);
    assert_eq!(code, 0);
    let text1 = std::fs::read_to_string(&m1).unwrap();
    let d: serde_json::Value = serde_json::from_str(&text1).unwrap();
    let c = &d["calibration"];
    for key in [
        "estimates_mm",
        "std_dev_mm",
        "correlations",
        "sensor_offsets",
        "parameter_set",
        "held",
        "chi2_per_dof",
        "data_file",
        "data_sha256",
        "date",
        "tool_version",
        "nominal",
    ] {
        assert!(!c[key].is_null(), "calibration.{key} missing");
    }
    assert!(d["name"].as_str().unwrap().contains("calibrated"));
    assert_eq!(c["parameter_set"], "paper15");
    assert_eq!(c["held"][0]["name"], "dyA3");
    assert!(
        c["held"][0]["reason"]
            .as_str()
            .unwrap()
            .contains("unidentifiable")
    );
    assert_eq!(c["std_dev_mm"]["dyA3"], serde_json::Value::Null);
    assert_eq!(c["estimates_mm"]["dq2"], id1["dq2"]);
    assert_eq!(c["sensor_offsets"]["s_mm"], id1["offsets"]["s_mm"]);
    assert_eq!(c["data_sha256"].as_str().unwrap().len(), 64);
    let corr = &c["correlations"];
    assert_eq!(corr["names"].as_array().unwrap().len(), 14);
    assert!((corr["matrix"][0][0].as_f64().unwrap() - 1.0).abs() < 1e-12);

    // Loadable by every --machine.
    let m = m1.to_str().unwrap();
    for args in [
        vec!["ik", "0", "0", "750", "--machine", m],
        vec!["fk", "773", "773", "773", "--machine", m],
        vec!["tool-ik", "0", "0", "1100", "0", "0", "1", "--machine", m],
        vec!["machine", "--machine", m],
        vec!["identifiability", "--machine", m],
        vec!["simulate", "--poses", "grid:1,8,3", "--machine", m],
        vec!["detectability", "--poses", "grid:1,8,3", "--machine", m],
        vec!["compensate", "--machine", m, "--spacing", "100"],
        vec!["diagnose", "--data", &data, "--machine", m],
    ] {
        let out = run(&args);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {}", text(&out));
    }
    // The calibrated IK moves the commands by the calibration (dq2 0.7 mm
    // in Table 2, against the nominal machine).
    let nominal = json(&run(&["ik", "0", "0", "750", "--json"]));
    let calibrated = json(&run(&["ik", "0", "0", "750", "--json", "--machine", m]));
    let shift = nominal["q2"].as_f64().unwrap() - calibrated["q2"].as_f64().unwrap();
    assert!(shift > 0.3 && shift < 1.2, "{shift}");

    // Identifying again against it keeps the rank rule: dyA3 held, and the
    // increments are zero within their uncertainty.
    let m2 = dir.join("again.json");
    let (code, id2, _) = identify(Path::new(&data), &["--machine", m], &m2);
    assert_eq!(code, 0);
    assert_eq!(id2["rank"], 14);
    assert_eq!(id2["std_dev"]["dyA3"], serde_json::Value::Null);
    assert_eq!(id2["dyA3"], 0.0);
    for name in ["dxB1", "dyB3", "dxA3", "dq1", "dq2", "dq3"] {
        let (v, sd) = (
            id2[name].as_f64().unwrap(),
            id2["std_dev"][name].as_f64().unwrap(),
        );
        assert!(v.abs() < 0.1 * sd, "{name}: {v} +- {sd}");
    }
    // The second file records the first one's nominal machine, and its
    // commands agree with the first one's to far below the uncertainty.
    let d2: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&m2).unwrap()).unwrap();
    assert_eq!(d2["calibration"]["nominal"], c["nominal"]);
    let again = json(&run(&[
        "ik",
        "0",
        "0",
        "750",
        "--json",
        "--machine",
        m2.to_str().unwrap(),
    ]));
    for q in ["q1", "q2", "q3"] {
        let d = (again[q].as_f64().unwrap() - calibrated[q].as_f64().unwrap()).abs();
        assert!(d < 1e-3, "{q}: {d}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_recalibration_keeps_a_record_the_file_is_checked_against() {
    let dir = workdir("trust-chain");
    let data = fixture("data/table2-grid-seed1.csv");
    let (m1, m2) = (dir.join("m1.json"), dir.join("m2.json"));
    assert_eq!(identify(Path::new(&data), &[], &m1).0, 0);
    let out = run(&[
        "identify",
        "--data",
        &data,
        "--machine",
        m1.to_str().unwrap(),
        "--write-machine",
        m2.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let d: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&m2).unwrap()).unwrap();
    // Relative to the first calibration, which the record keeps.
    assert!(d["calibration"]["relative_to_machine"]["calibration"].is_null());
    assert!(d["calibration"]["relative_to_machine"]["placement"].is_object());
    assert_eq!(
        run(&["ik", "0", "0", "750", "--machine", m2.to_str().unwrap()])
            .status
            .code(),
        Some(0)
    );
    // A hand edit of the second file is caught as the first one's would be.
    let mut e = d.clone();
    let q = e["leg_offsets_mm"][2].as_f64().unwrap();
    e["leg_offsets_mm"][2] = (q + 0.01).into();
    std::fs::write(&m2, serde_json::to_string(&e).unwrap()).unwrap();
    let out = run(&["ik", "0", "0", "750", "--machine", m2.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out).contains("leg_offsets_mm[2]"), "{}", text(&out));
    // A record that says the fit did not converge (as tricept writes it,
    // sealed: a hand edit of `converged` is refused) loads with a warning.
    let mut c = tricept_kinematics::MachineDescription::from_file(&m1).unwrap();
    c.calibration.as_mut().unwrap().converged = false;
    let edited = dir.join("m1-edited.json");
    std::fs::write(&edited, c.to_json()).unwrap();
    let out = run(&["ik", "0", "0", "750", "--machine", edited.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out).contains("`calibration.converged` edited"),
        "{}",
        text(&out)
    );
    c.seal();
    std::fs::write(&m1, c.to_json()).unwrap();
    let out = run(&["ik", "0", "0", "750", "--machine", m1.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stderr).contains("did not converge"));
    std::fs::remove_dir_all(&dir).ok();
}
