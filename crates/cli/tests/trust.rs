//! A calibration a user can trust, against the real binary: exit codes that
//! mean something (0 converged and adequate, 3 converged but inadequate, 4
//! not converged, 2 bad input), messages that name the likely cause, a
//! machine file that records its calibration and round-trips, and the
//! deployed extended model doing on the simulated machine what the
//! diagnosis said it would.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tricept() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tricept"))
}

fn workdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tricept-trust-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn fixture(name: &str) -> String {
    format!("{}/../../fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn run(args: &[&str]) -> Output {
    let out = tricept().args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    out
}

fn json(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{e}: {}\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// The comments, header and rows of a CSV text.
fn parts(csv: &str) -> (Vec<&str>, Vec<String>, Vec<Vec<String>>) {
    let comments: Vec<&str> = csv.lines().filter(|l| l.starts_with('#')).collect();
    let mut rows = csv.lines().filter(|l| !l.starts_with('#'));
    let header = rows
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = rows
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (comments, header, rows)
}

/// Writes `csv` with each row passed through `f` (header names in `h`).
fn rewrite(
    csv: &str,
    path: &Path,
    header: impl Fn(&mut Vec<String>),
    f: impl Fn(usize, &[String], &mut Vec<String>),
) {
    let (comments, mut h, rows) = parts(csv);
    let names = h.clone();
    header(&mut h);
    let mut s = comments.join("\n") + "\n" + &h.join(",") + "\n";
    for (j, r) in rows.iter().enumerate() {
        let mut r = r.clone();
        f(j, &names, &mut r);
        s += &(r.join(",") + "\n");
    }
    std::fs::write(path, s).unwrap();
}

fn col(names: &[String], c: &str) -> usize {
    names.iter().position(|n| n == c).unwrap()
}

/// Identify with `--json` and `--write-machine`; asserts the exit code
/// matches the JSON verdict and returns (code, json, stderr).
fn identify(data: &Path, extra: &[&str], machine_out: &Path) -> (i32, serde_json::Value, String) {
    let mut args = vec![
        "identify".to_string(),
        "--data".into(),
        data.display().to_string(),
        "--json".into(),
        "--write-machine".into(),
        machine_out.display().to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    let out = tricept().args(&args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!stderr.contains("panicked"), "{stderr}");
    let code = out.status.code().unwrap();
    let v = json(&out);
    let expected = match (
        v["converged"].as_bool(),
        v["adequate"].as_bool(),
        v["worthwhile"].as_bool(),
    ) {
        (Some(false), _, _) => 4,
        (Some(true), Some(false), _) | (Some(true), Some(true), Some(false)) => 3,
        (Some(true), Some(true), Some(true)) => 0,
        _ => panic!("no verdict in {v}"),
    };
    assert_eq!(
        code, expected,
        "exit code against the JSON verdict: {stderr}"
    );
    (code, v, stderr)
}

#[test]
fn data_that_cannot_come_from_the_machine_get_a_non_zero_code_and_a_named_cause() {
    let dir = workdir("causes");
    let good = std::fs::read_to_string(fixture("data/table2-grid-seed1.csv")).unwrap();
    let cases: Vec<(&str, PathBuf, Option<String>, &str)> = {
        let swap_angles = dir.join("swap-angles.csv");
        rewrite(
            &good,
            &swap_angles,
            |h| {
                let (i, j) = (col(h, "phi"), col(h, "theta"));
                h.swap(i, j);
            },
            |_, _, _| {},
        );
        let swap_legs = dir.join("swap-legs.csv");
        rewrite(
            &good,
            &swap_legs,
            |h| {
                let (i, j) = (col(h, "q1"), col(h, "q2"));
                h.swap(i, j);
            },
            |_, _, _| {},
        );
        let metres = dir.join("metres.csv");
        rewrite(
            &good,
            &metres,
            |_| {},
            |_, names, r| {
                let s = col(names, "s");
                r[s] = (r[s].parse::<f64>().unwrap() / 1000.0).to_string();
            },
        );
        vec![
            (
                "swapped phi and theta",
                swap_angles,
                None,
                "phi and theta are exchanged",
            ),
            (
                "swapped q1 and q2",
                swap_legs,
                None,
                "q1 and q2 are exchanged",
            ),
            ("s in metres", metres, None, "logged in m, not mm"),
            (
                "the wrong machine file",
                PathBuf::from(fixture("data/table2-grid-seed1.csv")),
                Some(fixture("machines/tricept-paper-y-first.json")),
                "the data fit the same machine with the x-first axis order",
            ),
        ]
    };
    for (name, data, machine, cause) in cases {
        let out_machine = dir.join(format!("{name}.json"));
        let extra: Vec<&str> = match &machine {
            Some(m) => vec!["--machine", m.as_str()],
            None => vec![],
        };
        let (code, v, stderr) = identify(&data, &extra, &out_machine);
        assert!(code == 3 || code == 4, "{name}: exit {code}");
        assert_eq!(v["consistent_with_machine"], false, "{name}");
        let warnings = v["warnings"].to_string();
        assert!(
            warnings.contains("wrong machine file") && warnings.contains("swapped columns"),
            "{name}: {warnings}"
        );
        assert!(warnings.contains(cause), "{name}: {warnings}");
        // Such a fit is never written without --force.
        assert!(!out_machine.exists(), "{name}: machine written");
        assert!(stderr.contains("not written"), "{name}: {stderr}");
    }
    // The issue's wrong-machine case converges: exit 3, not 4.
    let (code, _, _) = identify(
        Path::new(&fixture("data/table2-grid-seed1.csv")),
        &["--machine", &fixture("machines/tricept-paper-y-first.json")],
        &dir.join("wrong.json"),
    );
    assert_eq!(code, 3);

    // Twenty rows at one pose: no geometry to identify; an input error.
    // Same commands, the readings of twenty rows (as a logger stuck on one
    // pose would write them).
    let one = dir.join("one-pose.csv");
    let (comments, header, rows) = parts(&good);
    let mut s = comments.join("\n") + "\n" + &header.join(",") + "\n";
    for r in rows.iter().take(20) {
        let mut r = r.clone();
        for c in ["q1", "q2", "q3"] {
            r[col(&header, c)] = "773".into();
        }
        s += &(r.join(",") + "\n");
    }
    std::fs::write(&one, s).unwrap();
    for verb in ["identify", "diagnose"] {
        let out = run(&[verb, "--data", one.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{verb}: {}", text(&out));
        assert!(
            text(&out).contains("1 distinct leg commands"),
            "{verb}: {}",
            text(&out)
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_converged_fit_that_does_not_explain_the_data_exits_3_and_names_diagnose() {
    let dir = workdir("inadequate");
    let data = fixture("data/diagnose-hidden-effect.csv");
    let (code, v, stderr) = identify(Path::new(&data), &[], &dir.join("m.json"));
    assert_eq!(code, 3);
    assert!(v["warnings"].to_string().contains("tricept diagnose"));
    // Not written: an exit-3 fit is deployed only with --force.
    assert!(!dir.join("m.json").exists());
    assert!(stderr.contains("not written"), "{stderr}");
    let (code, _, _) = identify(Path::new(&data), &["--force"], &dir.join("m.json"));
    assert_eq!(code, 3);
    // Written with --force, and marked: forced, not adequate.
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("m.json")).unwrap()).unwrap();
    assert_eq!(m["calibration"]["adequate"], false);
    assert_eq!(m["calibration"]["forced"], true);
    assert!(
        m["name"]
            .as_str()
            .unwrap()
            .contains("does not explain the data")
    );
    // The text report names the diagnosis too.
    let out = run(&["identify", "--data", &data]);
    assert_eq!(out.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&out.stdout).contains("run `tricept diagnose`"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_forced_machine_is_marked_and_warned_about_when_loaded() {
    let dir = workdir("forced");
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
    assert!(String::from_utf8_lossy(&out.stderr).contains("--force"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_calibrated_machine_file_is_complete_loads_everywhere_and_round_trips() {
    let dir = workdir("roundtrip");
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
fn deploying_the_diagnosis_delivers_its_gain_on_the_simulated_machine() {
    // The worked example of docs/diagnosis.md: random geometric errors up
    // to 0.5 mm (seed 4) and legs of 33.6 N/um at 1 m, which the geometric
    // model absorbs into a 5 mm leg-length error.
    let dir = workdir("deploy");
    let data = fixture("data/diagnose-hidden-effect.csv");
    let (truth, effect) = (
        "random:0.5,4",
        r#"{"effect":"compliance","stiffness_n_per_um_at_1m":33.6}"#,
    );
    let ext = dir.join("extended.json");
    let geo = dir.join("geometric.json");
    let d = json(&run(&[
        "diagnose",
        "--data",
        &data,
        "--json",
        "--write-machine",
        ext.to_str().unwrap(),
    ]));
    // The geometric-only calibration is exit 3: written only when forced.
    let (code, _, _) = identify(Path::new(&data), &["--force"], &geo);
    assert_eq!(code, 3);
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&ext).unwrap()).unwrap();
    // The named static effect is in the file, as the diagnosis estimated it.
    let c = file["leg_effects"]["compliance_um_per_kn_at_1m"]
        .as_f64()
        .unwrap();
    let reported = d["extended"]["compliance.compliance_um_per_kn_at_1m"]["value"]
        .as_f64()
        .unwrap();
    assert!((c - reported).abs() < 1e-6 * reported, "{c} vs {reported}");

    // The maps of the true machine commanded through each file.
    // The forced geometric file is compensated only with --force too.
    let map = |machine: &Path, name: &str, force: &str| -> Vec<[f64; 3]> {
        let out_dir = dir.join(name);
        let mut args = vec![
            "compensate",
            "--machine",
            machine.to_str().unwrap(),
            "--truth",
            truth,
            "--truth-effect",
            effect,
            "--spacing",
            "50",
            "--map",
            out_dir.to_str().unwrap(),
        ];
        if !force.is_empty() {
            args.push(force);
        }
        let out = run(&args);
        // A forced compensation still says in its code that it is untrusted.
        let expected = if force.is_empty() { 0 } else { 3 };
        assert_eq!(out.status.code(), Some(expected), "{}", text(&out));
        let csv = std::fs::read_to_string(out_dir.join("map.csv")).unwrap();
        let (_, h, rows) = parts(&csv);
        let (x, y, z) = (
            col(&h, "after_dx"),
            col(&h, "after_dy"),
            col(&h, "after_dz"),
        );
        rows.iter()
            .map(|r| [x, y, z].map(|i| r[i].parse::<f64>().unwrap()))
            .collect()
    };
    let (with_geo, with_ext) = (map(&geo, "geo", "--force"), map(&ext, "ext", ""));
    let n = with_geo.len() as f64;
    let moved: f64 = with_geo
        .iter()
        .zip(&with_ext)
        .map(|(a, b)| {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        })
        .sum::<f64>()
        / n;
    let norm = |v: &[f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let error_geo = with_geo.iter().map(norm).sum::<f64>() / n;
    let error_ext = with_ext.iter().map(norm).sum::<f64>() / n;
    // What the diagnosis said the extended calibration changes (platform
    // displacement on the middle plane, 50 mm lattice) is what commanding
    // the simulated machine through the written file changes.
    let predicted = d["gain"]["volumetric_mean_mm"].as_f64().unwrap();
    assert!(
        (moved - predicted).abs() < 0.01 * predicted,
        "moved {moved} mm, diagnosis {predicted} mm"
    );
    // And the gain is real: the extended file puts the machine within a few
    // tenths of a mm where the geometric one is almost 5 mm off.
    assert!(
        error_geo > 4.0 && error_ext < 0.2,
        "{error_geo} {error_ext}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn batch_kinematics_write_the_json_keys_as_csv_columns() {
    let dir = workdir("batch");
    let points = dir.join("points.csv");
    std::fs::write(
        &points,
        "\u{feff}# targets\nz,x,y\n750,0,0\n700,-120.5,80\n",
    )
    .unwrap();
    let out = run(&["ik", "--input", points.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let csv = String::from_utf8(out.stdout).unwrap();
    let (_, header, rows) = parts(&csv);
    let single = json(&run(&["ik", "-120.5", "80", "700", "--json"]));
    let keys: Vec<String> = single.as_object().unwrap().keys().cloned().collect();
    assert_eq!(header, keys);
    // (serde_json reads floats to within an ulp, hence the tolerance.)
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-15 * a.abs().max(b.abs());
    for (k, v) in header.iter().zip(&rows[1]) {
        assert!(
            same(v.parse::<f64>().unwrap(), single[k].as_f64().unwrap()),
            "{k}"
        );
    }
    // fk from stdin, fed the ik output: back to the points.
    let mut child = tricept()
        .args(["fk", "--input", "-"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    {
        use std::io::Write;
        let mut stdin = child.stdin.take().unwrap();
        let q: Vec<String> = rows
            .iter()
            .map(|r| format!("{},{},{}", r[3], r[4], r[5]))
            .collect();
        write!(stdin, "q1,q2,q3\n{}\n", q.join("\n")).unwrap();
    }
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let (_, h, back) = parts(std::str::from_utf8(&out.stdout).unwrap());
    let single_fk = json(&run(&["fk", "773", "773", "773", "--json"]));
    let keys: Vec<String> = single_fk.as_object().unwrap().keys().cloned().collect();
    assert_eq!(h, keys);
    let x = col(&h, "x");
    assert!((back[1][x].parse::<f64>().unwrap() + 120.5).abs() < 1e-9);
    // tool-ik too.
    let tools = dir.join("tools.csv");
    std::fs::write(&tools, "x,y,z,ax,ay,az\n150,100,1080,0.2,-0.1,1\n").unwrap();
    let out = run(&["tool-ik", "--input", tools.to_str().unwrap()]);
    let single = json(&run(&[
        "tool-ik", "150", "100", "1080", "0.2", "-0.1", "1", "--json",
    ]));
    let (_, h, r) = parts(std::str::from_utf8(&out.stdout).unwrap());
    assert_eq!(h.len(), single.as_object().unwrap().len());
    assert!(same(
        r[0][col(&h, "h2")].parse::<f64>().unwrap(),
        single["h2"].as_f64().unwrap()
    ));
    // A point out of reach stops the batch with its line, exit 2.
    std::fs::write(&points, "x,y,z\n0,0,750\n\n0,0,3000\n").unwrap();
    let out = run(&["ik", "--input", points.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out).contains("line 4"), "{}", text(&out));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn compensate_writes_clean_csv_maps_and_checks_its_arguments() {
    let dir = workdir("compensate");
    let data = fixture("data/table2-grid-seed1.csv");
    let targets = dir.join("targets.csv");
    std::fs::write(&targets, "x,y,z\n0,0,750\n100,-50,700\n").unwrap();
    let out = run(&[
        "compensate",
        "--data",
        &data,
        "--targets",
        targets.to_str().unwrap(),
        "--truth",
        "table2",
        "--map",
        dir.join("map").to_str().unwrap(),
        "--spacing",
        "50",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    // stdout is the CSV and nothing else; the report is on stderr.
    let csv = String::from_utf8(out.stdout).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("x,y,z,q1,q2,q3"));
    assert_eq!(lines.count(), 2);
    assert!(String::from_utf8_lossy(&out.stderr).contains("after"));
    for f in ["map.csv", "correction.svg", "before.svg", "after.svg"] {
        assert!(dir.join("map").join(f).exists(), "{f}");
    }
    let map = std::fs::read_to_string(dir.join("map/map.csv")).unwrap();
    let (_, h, rows) = parts(&map);
    assert!(h.contains(&"before_mm".to_string()) && h.contains(&"after_mm".to_string()));
    let (b, a) = (col(&h, "before_mm"), col(&h, "after_mm"));
    let mean = |i: usize| {
        rows.iter()
            .map(|r| r[i].parse::<f64>().unwrap())
            .sum::<f64>()
            / rows.len() as f64
    };
    assert!(mean(a) < 0.5 * mean(b));
    // Arguments: a real message for a negative spacing, exit 2 off the plane.
    for (args, needle) in [
        (vec!["--spacing", "-5"], "--spacing"),
        (vec!["--plane-z", "3000"], "outside the workspace"),
        (vec!["--plane-z", "-700"], "outside the workspace"),
    ] {
        let mut all = vec!["compensate", "--data", &data];
        all.extend(args);
        let out = run(&all);
        assert_eq!(out.status.code(), Some(2), "{all:?}");
        assert!(text(&out).contains(needle), "{}", text(&out));
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn absurd_machines_and_flags_are_refused_clearly() {
    let dir = workdir("absurd");
    let huge = dir.join("huge.json");
    std::fs::write(
        &huge,
        tricept_kinematics::description::PAPER_MACHINE_JSON.replace("288.7", "1e200"),
    )
    .unwrap();
    let out = run(&["ik", "0", "0", "750", "--machine", huge.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out).contains("not the size of a machine"),
        "{}",
        text(&out)
    );
    // --json on machine and simulate.
    let m = json(&run(&["machine", "--json"]));
    assert_eq!(m["workspace"]["radius_mm"], 400.0);
    let out_csv = dir.join("s.csv");
    let s = json(&run(&[
        "simulate",
        "--poses",
        "grid:1,8,3",
        "--json",
        "--out",
        out_csv.to_str().unwrap(),
    ]));
    let rows = std::fs::read_to_string(&out_csv)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .count()
        - 1;
    assert_eq!(s["poses"], rows as u64);
    // Text output carries units.
    let out = run(&["ik", "0", "0", "750"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains(" mm\n"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_single_gross_reading_is_rejected_by_line_not_fatal() {
    // A 10 mm scale glitch on the first data row (line 7) and a 0.1 rad
    // encoder jump: rejected by line, the fit converged and adequate.
    let dir = workdir("glitch");
    let good = std::fs::read_to_string(fixture("data/table2-grid-seed1.csv")).unwrap();
    let first_data_line = good.lines().position(|l| !l.starts_with('#')).unwrap() + 2;
    for (name, column, size, row) in [("glitch", "s", 10.0, 0usize), ("jump", "phi", 0.1, 10)] {
        let path = dir.join(format!("{name}.csv"));
        rewrite(
            &good,
            &path,
            |_| {},
            |j, names, r| {
                if j == row {
                    let c = col(names, column);
                    r[c] = (r[c].parse::<f64>().unwrap() + size).to_string();
                }
            },
        );
        let (code, v, _) = identify(&path, &[], &dir.join(format!("{name}.json")));
        assert_eq!(code, 0, "{name}: {v}");
        let line = (first_data_line + row) as u64;
        assert_eq!(v["rejected"][0]["line"], line, "{name}");
        assert_eq!(v["rejected"][0]["pose"], row as u64 + 1, "{name}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The trilinear lookup of `table.csv` at `r`, read the way a controller
/// would (this test's own implementation, from the documented format).
fn lookup(
    nodes: &std::collections::HashMap<[i64; 3], [f64; 3]>,
    origin: [f64; 3],
    h: f64,
    r: [f64; 3],
) -> [f64; 3] {
    let last: Vec<i64> = (0..3)
        .map(|a| nodes.keys().map(|k| k[a]).max().unwrap())
        .collect();
    let mut cell = [0i64; 3];
    let mut t = [0.0; 3];
    for a in 0..3 {
        let u = (r[a] - origin[a]) / h;
        // A point on the grid's upper face belongs to the last cell.
        cell[a] = (u.floor() as i64).clamp(0, last[a] - 1);
        t[a] = u - cell[a] as f64;
    }
    let mut out = [0.0; 3];
    for corner in 0..8 {
        let b = [corner & 1, corner >> 1 & 1, corner >> 2 & 1];
        let w: f64 = (0..3)
            .map(|a| if b[a] == 1 { t[a] } else { 1.0 - t[a] })
            .product();
        let v = nodes[&[cell[0] + b[0], cell[1] + b[1], cell[2] + b[2]]];
        for l in 0..3 {
            out[l] += w * v[l];
        }
    }
    out
}

#[test]
fn the_table_interpolation_error_is_what_the_docs_state() {
    let dir = workdir("table");
    let docs = std::fs::read_to_string(format!(
        "{}/../../docs/data-format.md",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    // The docs' row for the Table 2 data: `| ... table2-grid-seed1.csv ... |
    // 50 mm | 0.382 um |`.
    let row = docs
        .lines()
        .find(|l| {
            l.starts_with('|') && l.contains("table2-grid-seed1.csv") && l.contains("--table")
        })
        .expect("docs/data-format.md states the table of the Table 2 data");
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    let stated_spacing: f64 = cells[cells.len() - 3]
        .trim_end_matches(" mm")
        .parse()
        .unwrap();
    let stated_um: f64 = cells[cells.len() - 2]
        .trim_end_matches(" um")
        .parse()
        .unwrap();

    let data = fixture("data/table2-grid-seed1.csv");
    let cal = dir.join("t2.json");
    let (code, _, _) = identify(Path::new(&data), &[], &cal);
    assert_eq!(code, 0);
    let out = run(&[
        "compensate",
        "--machine",
        cal.to_str().unwrap(),
        "--table",
        dir.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let v = json(&out);
    let spacing = v["table"]["spacing_mm"].as_f64().unwrap();
    let error_um = v["table"]["interpolation_error_um"].as_f64().unwrap();
    assert_eq!(spacing, stated_spacing);
    assert_eq!(format!("{error_um:.3}"), format!("{stated_um:.3}"));
    assert!(error_um < 1.0);

    // Measured again from the file alone: the exact corrections from
    // `ik --input` on both machines, the lookup from table.csv.
    let csv = std::fs::read_to_string(dir.join("table.csv")).unwrap();
    let (_, h, rows) = parts(&csv);
    let f = |r: &Vec<String>, c: &str| r[col(&h, c)].parse::<f64>().unwrap();
    let mut nodes = std::collections::HashMap::new();
    for r in &rows {
        let idx = ["i", "j", "k"].map(|c| f(r, c) as i64);
        nodes.insert(idx, ["dq1", "dq2", "dq3"].map(|c| f(r, c)));
    }
    let first = &rows[0];
    let origin = [
        f(first, "x") - f(first, "i") * spacing,
        f(first, "y") - f(first, "j") * spacing,
        f(first, "z") - f(first, "k") * spacing,
    ];
    let fine = spacing / 4.0;
    let mut lattice = String::from("x,y,z\n");
    let mut points = Vec::new();
    for k in 0..=((200.0 / fine) as i64) {
        for j in -((400.0 / fine) as i64)..=((400.0 / fine) as i64) {
            for i in -((400.0 / fine) as i64)..=((400.0 / fine) as i64) {
                let p = [i as f64 * fine, j as f64 * fine, 650.0 + k as f64 * fine];
                if p[0].hypot(p[1]) <= 400.0 {
                    lattice += &format!("{},{},{}\n", p[0], p[1], p[2]);
                    points.push(p);
                }
            }
        }
    }
    let lattice_file = dir.join("lattice.csv");
    std::fs::write(&lattice_file, lattice).unwrap();
    let ik = |machine: Option<&Path>| -> Vec<[f64; 3]> {
        let mut args = vec!["ik", "--input", lattice_file.to_str().unwrap()];
        if let Some(m) = machine {
            args.extend(["--machine", m.to_str().unwrap()]);
        }
        let out = run(&args);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out));
        let (_, h, rows) = parts(std::str::from_utf8(&out.stdout).unwrap());
        rows.iter()
            .map(|r| ["q1", "q2", "q3"].map(|c| r[col(&h, c)].parse::<f64>().unwrap()))
            .collect()
    };
    let (nominal, calibrated) = (ik(None), ik(Some(&cal)));
    let mut worst: f64 = 0.0;
    for (n, (p, (a, b))) in points
        .iter()
        .zip(nominal.iter().zip(&calibrated))
        .enumerate()
    {
        let looked_up = lookup(&nodes, origin, spacing, *p);
        for l in 0..3 {
            let e = (looked_up[l] - (b[l] - a[l])).abs();
            assert!(e.is_finite(), "point {n}");
            worst = worst.max(e);
        }
    }
    assert!(
        (worst * 1e3 - error_um).abs() < 1e-6,
        "re-measured {} um, stated {error_um} um",
        worst * 1e3
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_dynamic_effects_are_exported_as_controller_parameters() {
    // Backlash, a thermal drift and leg lead hidden in a campaign that
    // visits each pose from both directions and logs the temperature.
    let dir = workdir("controller");
    let data = dir.join("dynamic.csv");
    let (backlash_um, expansion, lead_ppm) = ([6.0, 5.0, 8.0], 11.5, [60.0, -40.0, 30.0]);
    let out = run(&[
        "simulate",
        "--truth",
        "random:0.3,2",
        "--poses",
        "random:150,3",
        "--both-directions",
        "--readings-per-pose",
        "10",
        "--truth-effect",
        &format!(r#"{{"effect":"backlash","um":{backlash_um:?}}}"#),
        "--truth-effect",
        &format!(r#"{{"effect":"thermal","drift_k":3,"expansion_ppm_per_k":{expansion}}}"#),
        "--truth-effect",
        &format!(r#"{{"effect":"leg-lead","ppm":{lead_ppm:?}}}"#),
        "--out",
        data.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let file = dir.join("dynamic.json");
    let out = run(&[
        "diagnose",
        "--data",
        data.to_str().unwrap(),
        "--write-machine",
        file.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let d: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let effects = &d["calibration"]["effects"];
    let check = |value: &serde_json::Value, name: &str, truth: f64| {
        let sd = effects[name]["std_dev"].as_f64().unwrap();
        let v = value.as_f64().unwrap();
        assert_eq!(v, effects[name]["value"].as_f64().unwrap(), "{name}");
        assert!(
            (v - truth).abs() < 5.0 * sd,
            "{name}: {v} +- {sd}, truth {truth}"
        );
    };
    let c = &d["controller"];
    for i in 0..3 {
        check(
            &c["backlash_um"][i],
            &format!("backlash.backlash{}_um", i + 1),
            backlash_um[i],
        );
        check(
            &d["leg_effects"]["lead_ppm"][i],
            &format!("leg-lead.lead{}_ppm", i + 1),
            lead_ppm[i],
        );
    }
    check(
        &c["thermal_expansion_ppm_per_k"],
        "thermal.expansion_ppm_per_k",
        expansion,
    );
    assert_eq!(c["reference_temperature_c"], 20.0);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn diagnose_says_in_its_exit_code_and_its_machine_file_what_it_deploys() {
    let dir = workdir("diagnose-deploy");
    let file = |name: &str| dir.join(name).to_str().unwrap().to_string();
    // Explained by a generic term: exit 0 with or without the file, and
    // the pitch error is in it as a compensation table per leg, applied by
    // ik and exported by compensate --table.
    let pitch = fixture("data/diagnose-pitch.csv");
    let out = run(&[
        "diagnose",
        "--data",
        &pitch,
        "--write-machine",
        &file("p.json"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("p.json")).unwrap()).unwrap();
    assert_eq!(m["calibration"]["forced"], false);
    assert_eq!(m["calibration"]["adequate"], true);
    let tables = m["leg_effects"]["tables"].as_array().unwrap();
    assert_eq!(tables.len(), 3, "{m}");
    for t in tables {
        assert_eq!(t["interpolation"], "linear");
        // At least 20 points per 10 mm period.
        assert!(t["step_mm"].as_f64().unwrap() <= 0.5, "{t}");
        let v: Vec<f64> = t["extra_length_um"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        // The fixture's pitch error: 4 um on each leg.
        let amplitude = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        assert!((2.0..8.0).contains(&amplitude), "{amplitude}");
    }
    let applies = m["calibration"]["applies"].to_string();
    assert!(applies.contains("compensation table"), "{applies}");
    // ik applies the tables: the file without them commands otherwise.
    let ik = |machine: &str| {
        let v = json(&run(&[
            "ik",
            "10",
            "20",
            "760",
            "--machine",
            machine,
            "--json",
        ]));
        [v["q1"].clone(), v["q2"].clone(), v["q3"].clone()]
    };
    // (Without the tables and without the record's digest of them: a file
    // as written before tables existed.)
    let mut plain = m.clone();
    plain["leg_effects"]
        .as_object_mut()
        .unwrap()
        .remove("tables");
    assert!(
        plain["calibration"]
            .as_object_mut()
            .unwrap()
            .remove("leg_tables_digest")
            .is_some(),
        "the record keeps a digest of the tables"
    );
    std::fs::write(dir.join("plain.json"), plain.to_string()).unwrap();
    let (with, without) = (ik(&file("p.json")), ik(&file("plain.json")));
    let moved = (0..3)
        .map(|i| (with[i].as_f64().unwrap() - without[i].as_f64().unwrap()).abs())
        .fold(0.0, f64::max);
    assert!(moved > 1e-4 && moved < 0.01, "{moved} mm");
    // compensate --table exports them.
    let out = run(&[
        "compensate",
        "--machine",
        &file("p.json"),
        "--table",
        &file("table"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let legs = std::fs::read_to_string(dir.join("table").join("leg-tables.csv")).unwrap();
    assert!(legs.contains("leg,command_mm,extra_length_um"), "{legs}");
    assert!(legs.contains("linear"), "{legs}");
    // A table that is not a table: exit 2, naming the file and the field.
    let mut bad = m.clone();
    bad["leg_effects"]["tables"][1]["step_mm"] = (-0.5).into();
    std::fs::write(dir.join("bad.json"), bad.to_string()).unwrap();
    let out = run(&["ik", "0", "0", "750", "--machine", &file("bad.json")]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(
        err.contains("bad.json") && err.contains("leg_effects.tables[1].step_mm"),
        "{err}"
    );
    // A table edited after the calibration, or removed while the record
    // still has it: the file does not match its record (exit 2).
    let mut edited = m.clone();
    let value = edited["leg_effects"]["tables"][0]["extra_length_um"][5]
        .as_f64()
        .unwrap();
    edited["leg_effects"]["tables"][0]["extra_length_um"][5] = (value + 1.0).into();
    let mut removed = m.clone();
    removed["leg_effects"]
        .as_object_mut()
        .unwrap()
        .remove("tables");
    for (name, d) in [("edited.json", edited), ("removed.json", removed)] {
        std::fs::write(dir.join(name), d.to_string()).unwrap();
        let out = run(&["ik", "0", "0", "750", "--machine", &file(name)]);
        assert_eq!(out.status.code(), Some(2), "{name}: {}", text(&out));
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(
            err.contains(name) && err.contains("leg_effects.tables differ"),
            "{err}"
        );
    }
    // A file written before the tables loads as it did.
    std::fs::write(dir.join("old.json"), plain.to_string()).unwrap();
    let out = run(&["fk", "800", "800", "800", "--machine", &file("old.json")]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    // Worse noise than stated and nothing to name: the verdict in the exit
    // code.
    let noisy = fixture("data/diagnose-noisy.csv");
    let out = run(&["diagnose", "--data", &noisy, "--json"]);
    assert_eq!(out.status.code(), Some(3), "{}", text(&out));
    assert_eq!(json(&out)["final_adequate"], false);
    // A scale gain reads exactly like an equal lead on every leg but puts
    // the platform elsewhere: the file deploys one and says so.
    let sim = run(&[
        "simulate",
        "--truth",
        "random:0.25,3",
        "--truth-effect",
        r#"{"effect":"scale-gain","ppm":80}"#,
        "--poses",
        "random:80",
        "--seed",
        "5",
        "--out",
        &file("sg.csv"),
    ]);
    assert_eq!(sim.status.code(), Some(0), "{}", text(&sim));
    let out = run(&[
        "diagnose",
        "--data",
        &file("sg.csv"),
        "--write-machine",
        &file("sg.json"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("sg.json")).unwrap()).unwrap();
    let warnings = m["calibration"]["warnings"].to_string();
    assert!(warnings.contains("scale-gain / leg-lead"), "{warnings}");
    assert!(warnings.contains("external length"), "{warnings}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The mean platform error (mm) of the simulated Table 2 machine on the
/// middle plane: uncalibrated, and commanded through `machine`.
fn true_errors(machine: &Path, extra: &[&str]) -> (f64, f64) {
    let mut args = vec![
        "compensate",
        "--machine",
        machine.to_str().unwrap(),
        "--truth",
        "table2",
        "--spacing",
        "50",
        "--json",
    ];
    args.extend(extra);
    let v = json(&run(&args));
    (
        v["before"]["mean_mm"].as_f64().unwrap(),
        v["after"]["mean_mm"].as_f64().unwrap(),
    )
}

#[test]
fn a_campaign_too_small_to_calibrate_is_refused_and_told_what_would_do() {
    let dir = workdir("small");
    // Eight poses: one on the axis and one off it on each of four planes.
    let data = dir.join("eight.csv");
    let out = run(&[
        "simulate",
        "--poses",
        "grid:1,1,4",
        "--out",
        data.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    let m = dir.join("m.json");
    let (code, v, stderr) = identify(&data, &[], &m);
    assert_eq!(code, 3, "{stderr}");
    assert_eq!(v["adequate"], true);
    assert_eq!(v["worthwhile"], false);
    let a = &v["predicted_accuracy"];
    assert!(
        a["after_rms_mm"].as_f64().unwrap() > 0.5 * a["before_rms_mm"].as_f64().unwrap(),
        "{a}"
    );
    assert!(!m.exists(), "a refused campaign must not be written");
    assert!(
        stderr.contains("not written: the campaign is too small to calibrate"),
        "{stderr}"
    );
    let w = v["warnings"].to_string();
    assert!(
        w.contains("`--poses optimal:") && w.contains("`--poses random:"),
        "{w}"
    );
    // Forced, the file makes the true machine worse than no calibration.
    let (code, _, _) = identify(&data, &["--force"], &m);
    assert_eq!(code, 3);
    let (before, after) = true_errors(&m, &["--force"]);
    assert!(
        after > before,
        "forced: {after} mm against {before} mm uncalibrated"
    );
    // The advised campaign is worthwhile, and in truth it is: on three
    // noise seeds it beats the uncalibrated machine by half.
    let advice = w
        .split("`--poses optimal:")
        .nth(1)
        .and_then(|s| s.split('`').next())
        .unwrap()
        .to_string();
    for seed in ["1", "2", "3"] {
        let out = run(&[
            "simulate",
            "--poses",
            &format!("optimal:{advice}"),
            "--seed",
            seed,
            "--out",
            data.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out));
        let (code, v, stderr) = identify(&data, &[], &m);
        assert_eq!(code, 0, "optimal:{advice}, seed {seed}: {stderr}");
        assert_eq!(v["worthwhile"], true);
        let (before, after) = true_errors(&m, &[]);
        assert!(
            after < 0.5 * before,
            "optimal:{advice}, seed {seed}: {after} mm against {before} mm"
        );
    }
    // A realistic campaign (40 random poses) is worthwhile without advice.
    run(&[
        "simulate",
        "--poses",
        "random:40,7",
        "--out",
        data.to_str().unwrap(),
    ]);
    let (code, v, _) = identify(&data, &[], &m);
    assert_eq!(code, 0);
    assert!(!v["warnings"].to_string().contains("cannot calibrate"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn compensate_refuses_a_fit_or_a_file_that_is_not_to_be_trusted() {
    let dir = workdir("compensate-rule");
    // The compliance fixture: exit 3 (a 12 um sag the geometry absorbs).
    let data = fixture("data/diagnose-hidden-effect.csv");
    let table = dir.join("table");
    let out = run(&[
        "compensate",
        "--data",
        &data,
        "--table",
        table.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(3), "{}", text(&out));
    assert!(text(&out).contains("not written: the model does not explain the data"));
    assert!(!table.join("table.csv").exists());
    let out = run(&[
        "compensate",
        "--data",
        &data,
        "--table",
        table.to_str().unwrap(),
        "--force",
    ]);
    assert_eq!(out.status.code(), Some(3));
    assert!(table.join("table.csv").exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_recalibration_keeps_a_record_the_file_is_checked_against() {
    let dir = workdir("chain");
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

/// `diagnose --help` names every effect of the registry, with where
/// `--write-machine` puts it (the list is the registry's, not a copy).
#[test]
fn diagnose_help_lists_the_vocabulary_and_its_deployment() {
    let out = tricept().args(["diagnose", "--help"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let help = String::from_utf8_lossy(&out.stdout);
    for e in tricept_model::effects::EffectName::ALL {
        let s = e.spec();
        let line = help
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{}:", s.name)))
            .unwrap_or_else(|| panic!("{} is not in the help:\n{help}", s.name));
        assert!(line.contains(s.deployment.label()), "{line}");
    }
}

/// Backlash logged with the `dir` columns' sign convention flipped fits as
/// a negative lost motion on every leg: the diagnosis rejects it as
/// implausible and names the convention as the likely cause (it cannot say
/// "the real cause is something else" about data whose only fault is a sign).
#[test]
fn backlash_with_a_flipped_dir_convention_names_the_convention() {
    let dir = workdir("dir-sign");
    let data = dir.join("backlash.csv");
    let out = run(&[
        "simulate",
        "--truth-effect",
        r#"{"effect":"backlash","um":[6,5,8]}"#,
        "--both-directions",
        "--poses",
        "random:80,2",
        "--out",
        data.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let as_logged = run(&["diagnose", "--data", data.to_str().unwrap()]);
    assert_eq!(as_logged.status.code(), Some(0), "{}", text(&as_logged));
    let flipped = dir.join("flipped.csv");
    rewrite(
        &std::fs::read_to_string(&data).unwrap(),
        &flipped,
        |_| {},
        |_, names, r| {
            for c in ["dir1", "dir2", "dir3"] {
                let i = col(names, c);
                r[i] = (-r[i].parse::<i32>().unwrap()).to_string();
            }
        },
    );
    let out = run(&["diagnose", "--data", flipped.to_str().unwrap()]);
    let report = text(&out);
    assert_eq!(out.status.code(), Some(3), "{report}");
    let rejected = report
        .lines()
        .find(|l| l.starts_with("rejected: backlash"))
        .unwrap_or_else(|| panic!("no rejected backlash line:\n{report}"));
    assert!(
        rejected.contains("likely cause") && rejected.contains("`dir`"),
        "{rejected}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
