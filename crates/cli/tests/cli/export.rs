//! `tricept export` end to end: the files and the JSON summary of a
//! calibrated machine, a format error past the tolerance (exit 3, the
//! limit named, nothing written), and the bad inputs (exit 2): an unknown
//! controller, a machine file without a calibration, an edited calibrated
//! file, an axis name the control cannot accept.

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
    let md = std::fs::read_to_string(out.join("MACHINE_DATA.TXT")).unwrap();
    assert!(md.contains("$MA_BACKLASH[0,Z1]=0.008"), "{md}");
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
        "--controller",
        "sinumerik",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("MD38000"), "{text}");
    assert!(text.contains("NOT written"), "{text}");
    assert!(!out.exists());
    // With the points the deployed table needs, it is written.
    let o = tricept(&[
        "export",
        "--machine",
        &fixture("pitch"),
        "--controller",
        "sinumerik",
        "--max-points",
        "2000",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(out.join("AX_EEC_INI.SPF").is_file());
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
        "fanuc only",
    );
}
