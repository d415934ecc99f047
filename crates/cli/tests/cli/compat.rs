//! Files written by an earlier tricept are read by this one: the
//! compatibility fixtures (fixtures/compat/, written by format version 1:
//! `fixtures/compat/make.sh`, never rewritten) load, command, report and
//! seed a calibration exactly as when they were written; the same files
//! without `format_version` (as written before the key existed) read as
//! version 1; a file declaring a newer version is refused by number.

use std::path::{Path, PathBuf};

use serde_json::Value;
use tricept_ident::kinematics::Machine;

use crate::support::{fixture, fresh_workdir, run, stderr};

fn compat(name: &str) -> String {
    fixture(&format!("compat/{name}"))
}

/// Every `format_version` key removed (at any depth) with the seal's
/// digests of it: a file as written before the key existed.
fn unversioned(v: &mut Value) {
    match v {
        Value::Object(map) => {
            map.remove("format_version");
            if let Some(Value::Object(seal)) = map.get_mut("seal") {
                seal.retain(|k, _| !k.ends_with("format_version"));
            }
            map.values_mut().for_each(unversioned);
        }
        Value::Array(items) => items.iter_mut().for_each(unversioned),
        _ => {}
    }
}

/// `name` rewritten into `dir` by `edit` (each line of a `.jsonl`).
fn rewritten(dir: &Path, name: &str, edit: fn(&mut Value)) -> PathBuf {
    let text = std::fs::read_to_string(compat(name)).unwrap();
    let out = dir.join(name.replace('/', "-"));
    let text = if name.ends_with(".jsonl") {
        let lines: Vec<String> = text
            .lines()
            .map(|l| {
                let mut v: Value = serde_json::from_str(l).unwrap();
                edit(&mut v);
                v.to_string()
            })
            .collect();
        lines.join("\n") + "\n"
    } else {
        let mut v: Value = serde_json::from_str(&text).unwrap();
        edit(&mut v);
        serde_json::to_string_pretty(&v).unwrap()
    };
    std::fs::write(&out, text).unwrap();
    out
}

fn newer(v: &mut Value) {
    v["format_version"] = 2.into();
}

fn code(args: &[&str]) -> (i32, String) {
    let out = run(args);
    (out.status.code().unwrap_or(-1), stderr(&out))
}

#[test]
fn every_compatibility_fixture_is_read() {
    let dir = fresh_workdir("compat");
    let p = |p: &PathBuf| p.to_str().unwrap().to_string();
    for name in [
        "machine.json",
        "machine-calibrated.json",
        "machine-deployed.json",
    ] {
        let m = Machine::load(compat(name)).unwrap();
        // Without the key: the same machine (the seal holds).
        let old = rewritten(&dir, name, unversioned);
        assert_eq!(Machine::load(&old).unwrap(), m, "{name}");
        let (c, e) = code(&["machine", "--machine", &p(&old)]);
        assert_eq!(c, 0, "{name}: {e}");
        // A newer version: refused by number, exit 2.
        let v2 = rewritten(&dir, name, newer);
        let (c, e) = code(&["machine", "--machine", &p(&v2)]);
        assert_eq!(c, 2, "{name}");
        assert!(e.contains("format_version 2"), "{name}: {e}");
    }
    assert!(
        Machine::load(compat("machine-deployed.json"))
            .unwrap()
            .has_leg_effects()
    );
    // The history and the export summary, read by the report (exit 0: the
    // calibration trusted, its last check unchanged).
    let page = p(&dir.join("page.html"));
    let cal = compat("machine-calibrated.json");
    let (c, e) = code(&[
        "report",
        "--machine",
        &cal,
        "--history",
        &compat("check-history.jsonl"),
        "--out",
        &page,
    ]);
    assert_eq!(c, 0, "{e}");
    let old = rewritten(&dir, "check-history.jsonl", unversioned);
    let (c, e) = code(&[
        "report",
        "--machine",
        &cal,
        "--history",
        &p(&old),
        "--out",
        &page,
    ]);
    assert_eq!(c, 0, "{e}");
    let v2 = rewritten(&dir, "check-history.jsonl", newer);
    let (c, e) = code(&[
        "report",
        "--machine",
        &cal,
        "--history",
        &p(&v2),
        "--out",
        &page,
    ]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("format_version 2"), "{e}");
    let dep = compat("machine-deployed.json");
    let (c, e) = code(&[
        "report",
        "--machine",
        &dep,
        "--export",
        &compat("export"),
        "--out",
        &page,
    ]);
    assert_eq!(c, 0, "{e}");
    // The prior seeds a calibration of a new machine of its batch.
    let data = compat("batch/m4.csv");
    let (c, e) = code(&[
        "identify",
        "--data",
        &data,
        "--prior",
        &compat("prior.json"),
    ]);
    assert_eq!(c, 0, "{e}");
    let old = rewritten(&dir, "prior.json", |v| {
        v.as_object_mut().unwrap().remove("format_version");
        v["seal"].as_object_mut().unwrap().remove("format_version");
    });
    let (c, e) = code(&["identify", "--data", &data, "--prior", &p(&old)]);
    assert_eq!(c, 0, "{e}");
    let v2 = rewritten(&dir, "prior.json", newer);
    let (c, e) = code(&["identify", "--data", &data, "--prior", &p(&v2)]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("format_version 2"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
