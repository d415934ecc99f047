//! Exit codes that mean something and messages that name the likely
//! cause: data that cannot come from the machine, a fit that does not
//! explain its data, a gross reading, absurd machines and flags, a
//! campaign too small to calibrate.

use super::*;

#[test]
fn data_that_cannot_come_from_the_machine_get_a_non_zero_code_and_a_named_cause() {
    let dir = workdir("trust-causes");
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
    // The wrong-machine case converges: exit 3, not 4.
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
    let dir = workdir("trust-inadequate");
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
fn absurd_machines_and_flags_are_refused_clearly() {
    let dir = workdir("trust-absurd");
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
    let dir = workdir("trust-glitch");
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
    let dir = workdir("trust-small");
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
        w.contains("poses `optimal:") && w.contains("poses `random:"),
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
        .split("poses `optimal:")
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
