//! What a controller reads: batch kinematics as CSV, compensation maps
//! and tables (their interpolation error as the docs state it), the
//! dynamic effects as controller parameters, and compensation refused on a
//! fit or file not to be trusted.

use super::*;

#[test]
fn batch_kinematics_write_the_json_keys_as_csv_columns() {
    let dir = workdir("trust-batch");
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
    // The CSV's columns are the JSON's keys after its `format_version`.
    let keys: Vec<String> = single.as_object().unwrap().keys().cloned().collect();
    assert_eq!(keys[0], "format_version");
    assert_eq!(header, keys[1..]);
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
    assert_eq!(h, keys[1..]);
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
    assert_eq!(h.len() + 1, single.as_object().unwrap().len());
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
    let dir = workdir("trust-compensate");
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
    let dir = workdir("trust-table");
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
    let dir = workdir("trust-controller");
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
fn compensate_refuses_a_fit_or_a_file_that_is_not_to_be_trusted() {
    let dir = workdir("trust-compensate-rule");
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
