//! `tricept export` end to end: the files and the JSON summary of a
//! calibrated machine, the control model (a Tricept's 840D sl by
//! default), a format error past the tolerance (exit 3, the limit named,
//! nothing written), the bad inputs (exit 2): an unknown controller, a
//! machine file without a calibration, an edited calibrated file, an axis
//! name the control cannot accept, an output that is a file or holds the
//! machine file; and the export folder as one unit under `kill -9`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tricept(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_tricept"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("panicked"),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn fixture(name: &str) -> String {
    format!(
        "{}/../export/tests/fixtures/{name}.json",
        env!("CARGO_MANIFEST_DIR")
    )
}

fn workdir(label: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tricept-export-{label}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn a_calibrated_machine_is_exported_with_its_summary() {
    let dir = workdir("ok");
    let out = dir.join("cnc");
    let o = tricept(&[
        "export",
        "--machine",
        &fixture("lead"),
        "--controller",
        "sinumerik",
        "--out",
        s(&out),
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["controller"], "sinumerik");
    // The family alone stands for a Tricept's control.
    assert_eq!(v["control"], "sinumerik-840d-sl");
    let files: Vec<&str> = v["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    for f in [
        "AX_EEC_INI.SPF",
        "MACHINE_DATA.TXT",
        "geometry.csv",
        "export.json",
    ] {
        assert!(files.contains(&f), "{files:?}");
        assert!(out.join(f).is_file(), "{f}");
    }
    let axes = v["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 3);
    for (i, a) in axes.iter().enumerate() {
        assert_eq!(a["leg"], i as u64 + 1);
        assert_eq!(a["axis"], ["X1", "Y1", "Z1"][i]);
        for key in ["points", "step_mm", "min_mm", "max_mm", "format_error_um"] {
            assert!(a[key].is_number(), "{key}: {a}");
        }
        // A lead error alone is linear: a linear table carries it exactly.
        assert!(a["format_error_um"].as_f64().unwrap() < 0.01, "{a}");
    }
    assert!(v["not_exported"].is_array());
    assert!(v["platform_error_um"].as_f64().unwrap() < 0.05, "{v}");
    // The leg lead of the calibration is in the table: leg 1's lead of
    // about 50 ppm over the table's span.
    let ini = std::fs::read_to_string(out.join("AX_EEC_INI.SPF")).unwrap();
    assert!(ini.contains("$AA_ENC_COMP_STEP[0,X1]="), "{ini}");
    // The file's backlash (its controller block) goes into MD32450.
    let machine: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixture("lead")).unwrap()).unwrap();
    let backlash_um = machine["controller"]["backlash_um"][2].as_f64().unwrap();
    let md = std::fs::read_to_string(out.join("MACHINE_DATA.TXT")).unwrap();
    assert!(
        md.contains(&format!("$MA_BACKLASH[0,Z1]={:.6}", backlash_um * 1e-3)),
        "{md}"
    );
}

#[test]
fn the_control_model_is_named_by_control_and_must_match_the_family() {
    let dir = workdir("model");
    let out = dir.join("cnc");
    let lead = fixture("lead");
    let run = |more: &[&str]| {
        let mut all = vec!["export", "--machine", &lead, "--json", "--out", s(&out)];
        all.extend_from_slice(more);
        tricept(&all)
    };
    // Without a flag: a Tricept's control.
    let o = run(&[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["control"], "sinumerik-840d-sl");
    let o = run(&["--control", "fanuc-30i"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (v["controller"].as_str(), v["control"].as_str()),
        (Some("fanuc"), Some("fanuc-30i"))
    );
    // A model of another family, an unknown model: exit 2.
    let o = run(&["--control", "fanuc-0i", "--controller", "heidenhain"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--control fanuc-0i is a fanuc control"),
        "{}",
        stderr(&o)
    );
    let o = run(&["--control", "tnc640"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("heidenhain-tnc640"), "{}", stderr(&o));
    // A hard limit of the model: the 808D's 200 points.
    let o = run(&["--control", "sinumerik-808d", "--max-points", "2000"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--max-points: 2000 is past the sinumerik-808d's 200"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn past_the_tolerance_nothing_is_written_and_the_limit_is_named() {
    let dir = workdir("limit");
    let out = dir.join("cnc");
    // A 4 um pitch error of 10 mm period on the 200 points of an 808D.
    let o = tricept(&[
        "export",
        "--machine",
        &fixture("pitch"),
        "--control",
        "sinumerik-808d",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("MD38000"), "{text}");
    assert!(text.contains("NOT written"), "{text}");
    assert!(!out.exists());
    // On a Tricept's own control, with its defaults, it is written.
    let o = tricept(&["export", "--machine", &fixture("pitch"), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(out.join("AX_EEC_INI.SPF").is_file());
}

#[test]
fn an_output_that_cannot_take_the_export_is_refused_before_any_work() {
    let dir = workdir("out");
    let refused = |machine: &Path, out: &Path, says: &str| {
        let before = listing(&dir);
        let o = tricept(&["export", "--machine", s(machine), "--out", s(out)]);
        assert_eq!(o.status.code(), Some(2), "{out:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{out:?}: {}", stderr(&o));
        assert_eq!(listing(&dir), before, "{out:?}: a file changed");
    };
    let lead = PathBuf::from(fixture("lead"));
    // A file, and `-`.
    let file = dir.join("cnc.txt");
    std::fs::write(&file, "mine").unwrap();
    refused(&lead, &file, "is not a folder");
    refused(&lead, Path::new("-"), "stdout");
    // A folder with other files in it.
    let mixed = dir.join("mixed");
    std::fs::create_dir(&mixed).unwrap();
    std::fs::write(mixed.join("notes.txt"), "mine").unwrap();
    refused(&lead, &mixed, "not a tricept export");
    // The machine file copied into an export folder under an export's
    // name, reached through a symbolic link, or hard-linked: exporting it
    // into that folder would replace it.
    let q = dir.join("q");
    let o = tricept(&["export", "--machine", s(&lead), "--out", s(&q)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for name in ["export.json", "geometry.csv"] {
        let inside = q.join(name);
        std::fs::copy(&lead, &inside).unwrap();
        refused(&inside, &q, "holds the machine file");
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&q, dir.join("q-link")).unwrap();
        refused(
            &q.join("export.json"),
            &dir.join("q-link"),
            "holds the machine file",
        );
        let outside = dir.join("cal.json");
        std::fs::copy(&lead, &outside).unwrap();
        std::fs::remove_file(q.join("geometry.csv")).unwrap();
        std::fs::hard_link(&outside, q.join("geometry.csv")).unwrap();
        refused(&outside, &q, "hard link");
    }
}

/// Every file's name and bytes under `dir`, for "nothing changed".
fn listing(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let meta = std::fs::symlink_metadata(&p).unwrap();
            if meta.is_dir() {
                stack.push(p);
            } else if meta.is_file() {
                out.push((p.clone(), std::fs::read(&p).unwrap()));
            } else {
                out.push((p, Vec::new()));
            }
        }
    }
    out.sort();
    out
}

/// A tiny seeded generator for the kill delays.
fn lcg(state: &mut u64) -> u64 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    *state >> 33
}

/// An export killed at any moment leaves the folder with the previous
/// export or the new one, whole (every file of one set, none of the
/// other), and nothing else but at most a stray temporary folder beside.
#[test]
fn kill_9_during_an_export_leaves_the_old_set_or_the_new_one() {
    let dir = workdir("kill");
    let out = dir.join("cnc");
    let export = |machine: &str| {
        let o = tricept(&["export", "--machine", &fixture(machine), "--out", s(&out)]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        listing(&out)
    };
    let new = export("pitch");
    let old = export("bowed");
    assert_ne!(old, new);
    let t0 = std::time::Instant::now();
    export("pitch");
    let span_us = (t0.elapsed().as_micros() as u64).max(1000) * 3 / 2;
    let mut state = 29;
    let (mut kept_old, mut complete_new) = (0, 0);
    for run in 0..60 {
        if listing(&out) != old {
            export("bowed");
        }
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_tricept"))
            .args(["export", "--machine", &fixture("pitch"), "--out", s(&out)])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_micros(lcg(&mut state) % span_us));
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
        let now = listing(&out);
        if now == old {
            kept_old += 1;
        } else if now == new {
            complete_new += 1;
        } else {
            panic!(
                "run {run}: a folder of neither set: {:?}",
                now.iter().map(|f| &f.0).collect::<Vec<_>>()
            );
        }
        // Beside the folder: at most stray temporaries of killed runs.
        for e in std::fs::read_dir(&dir).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().into_owned();
            assert!(name == "cnc" || name.starts_with(".cnc.tmp-"), "{name}");
        }
    }
    eprintln!("TALLY export kill -9: {kept_old} old, {complete_new} new, 0 mixed of 60");
    assert!(
        kept_old > 0 && complete_new > 0,
        "{kept_old} {complete_new}"
    );
}

#[test]
fn bad_inputs_are_exit_2_and_say_why() {
    let dir = workdir("bad");
    let out = dir.join("cnc");
    // Exit 2 with `says` in the message, and nothing written.
    let refused = |machine: &str, controller: &str, more: &[&str], says: &str| {
        let mut all = vec![
            "export",
            "--out",
            s(&out),
            "--machine",
            machine,
            "--controller",
            controller,
        ];
        all.extend_from_slice(more);
        let o = tricept(&all);
        assert_eq!(o.status.code(), Some(2), "{all:?}");
        assert!(stderr(&o).contains(says), "{all:?}: {}", stderr(&o));
        assert!(!out.exists());
    };
    let lead = fixture("lead");
    refused(&lead, "haas", &[], "haas");
    let nominal = format!(
        "{}/../../fixtures/machines/tricept-paper.json",
        env!("CARGO_MANIFEST_DIR")
    );
    refused(
        &nominal,
        "fanuc",
        &[],
        "nothing to compensate beyond the nominal",
    );
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&lead).unwrap()).unwrap();
    v["leg_offsets_mm"][0] = serde_json::json!(0.9);
    let edited = dir.join("edited.json");
    std::fs::write(&edited, v.to_string()).unwrap();
    refused(s(&edited), "heidenhain", &[], "leg_offsets_mm[0]");
    refused(&lead, "fanuc", &["--axis-names", "U,V,Q7"], "`Q7`");
    // A reference point off the stroke, a Fanuc option for another control.
    refused(
        &lead,
        "sinumerik",
        &["--reference-mm", "0,800,800"],
        "--reference-mm",
    );
    refused(
        &lead,
        "heidenhain",
        &["--detection-unit-um", "0.1"],
        "--detection-unit-um: applies to a fanuc control only",
    );
}
