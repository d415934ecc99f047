//! The diagnosis deployed: its gain delivered on the simulated machine,
//! its exit code and machine file saying what it deploys, its help naming
//! the vocabulary, a flipped sign convention named as the cause.

use super::*;

#[test]
fn deploying_the_diagnosis_delivers_its_gain_on_the_simulated_machine() {
    // The worked example of docs/diagnosis.md: random geometric errors up
    // to 0.5 mm (seed 4) and legs of 33.6 N/um at 1 m, which the geometric
    // model absorbs into a 5 mm leg-length error.
    let dir = workdir("trust-deploy");
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
fn diagnose_says_in_its_exit_code_and_its_machine_file_what_it_deploys() {
    let dir = workdir("trust-diagnose-deploy");
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
    // (Without the tables: the same geometry as a plain description, its
    // sealed record removed, which every edit of a sealed file needs.)
    let mut plain = m.clone();
    plain["leg_effects"]
        .as_object_mut()
        .unwrap()
        .remove("tables");
    assert!(
        plain
            .as_object_mut()
            .unwrap()
            .remove("calibration")
            .is_some_and(|c| c.get("leg_tables_digest").is_some()),
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
    let dir = workdir("trust-dir-sign");
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
