//! `tricept schema NAME` and the outputs it describes: every verb's
//! `--json` and every file tricept writes validates against its JSON
//! Schema (read by the `jsonschema` crate, a validator written from the
//! JSON Schema standard, not from our writer); each schema refuses its
//! document with another `format_version` or a required key missing, so
//! that a schema cannot be one that accepts anything.

use std::path::Path;

use serde_json::Value;

use crate::support::{fixture, fresh_workdir, run_in, stderr};

/// `tricept schema NAME`, parsed; it is the file docs/schema/NAME.json.
fn schema(name: &str) -> Value {
    let out = run_in(Path::new("."), &["schema", name]);
    assert_eq!(out.status.code(), Some(0), "{name}: {}", stderr(&out));
    let printed: Value = serde_json::from_slice(&out.stdout).unwrap();
    let file = format!(
        "{}/../../docs/schema/{name}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let kept: Value = serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap();
    assert_eq!(printed, kept, "{name}");
    printed
}

/// Every object of `text` (one JSON document, or one per line).
fn documents(text: &str) -> Vec<Value> {
    match serde_json::from_str::<Value>(text) {
        Ok(v) => vec![v],
        Err(_) => text
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| serde_json::from_str(l).unwrap())
            .collect(),
    }
}

/// Asserts every document of `text` is valid against schema `name`, and
/// that the schema refuses it changed (another version, a key missing).
fn valid(name: &str, text: &str) {
    let schema = schema(name);
    let validator = jsonschema::draft202012::new(&schema).unwrap();
    let docs = documents(text);
    assert!(!docs.is_empty(), "{name}: no output");
    for doc in docs {
        let errors: Vec<String> = validator.iter_errors(&doc).map(|e| e.to_string()).collect();
        assert!(errors.is_empty(), "{name}: {errors:?}");
        assert_eq!(doc["format_version"], 1, "{name}");
        let mut newer = doc.clone();
        newer["format_version"] = 2.into();
        assert!(!validator.is_valid(&newer), "{name}: version 2 accepted");
        let required = schema["required"].as_array().unwrap();
        let last = required.last().unwrap().as_str().unwrap();
        let mut missing = doc.clone();
        missing.as_object_mut().unwrap().remove(last);
        assert!(
            !validator.is_valid(&missing),
            "{name}: without `{last}` accepted"
        );
    }
}

/// Runs `tricept args` in `dir`, asserting exit code `code`; its stdout.
fn output(dir: &Path, code: i32, args: &[&str]) -> String {
    let out = run_in(dir, args);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {}", stderr(&out));
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn every_schema_is_listed_and_printed_as_kept() {
    let list = output(Path::new("."), 0, &["schema"]);
    let names: Vec<&str> = list
        .lines()
        .skip(1)
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    for name in [
        "machine",
        "identify",
        "diagnose",
        "check",
        "export",
        "prior",
        "check-history",
        "export-summary",
    ] {
        assert!(names.contains(&name), "{name} not in {names:?}");
    }
    let dir = format!("{}/../../docs/schema", env!("CARGO_MANIFEST_DIR"));
    let files = std::fs::read_dir(dir).unwrap().count();
    assert_eq!(names.len(), files, "{names:?}");
    for name in names {
        let s = schema(name);
        assert!(jsonschema::meta::is_valid(&s), "{name}: not a JSON Schema");
    }
    let out = run_in(Path::new("."), &["schema", "no-such"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("no schema `no-such`"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn every_json_output_and_written_file_validates_against_its_schema() {
    let dir = fresh_workdir("schema-outputs");
    let d = dir.as_path();
    let data = fixture("data/table2-grid-seed1.csv");
    let lead = fixture("compat/lead.csv");
    let batch = |i: u32| fixture(&format!("compat/batch/m{i}.csv"));
    let (b1, b2, b3) = (batch(1), batch(2), batch(3));
    let json = |code: i32, args: &[&str]| {
        let mut args = args.to_vec();
        args.push("--json");
        output(d, code, &args)
    };
    valid("ik", &json(0, &["ik", "0", "0", "750"]));
    valid("fk", &json(0, &["fk", "800", "800", "800"]));
    valid(
        "tool-ik",
        &json(0, &["tool-ik", "0", "0", "900", "0", "0", "1"]),
    );
    valid("identifiability", &json(0, &["identifiability"]));
    valid(
        "identify",
        &json(
            0,
            &["identify", "--data", &data, "--write-machine", "cal.json"],
        ),
    );
    valid(
        "machine",
        &std::fs::read_to_string(d.join("cal.json")).unwrap(),
    );
    valid("machine", &output(d, 0, &["machine", "--json"]));
    valid("simulate", &json(0, &["simulate", "--out", "sim.csv"]));
    valid(
        "diagnose",
        &json(
            0,
            &["diagnose", "--data", &lead, "--write-machine", "dep.json"],
        ),
    );
    valid(
        "machine",
        &std::fs::read_to_string(d.join("dep.json")).unwrap(),
    );
    valid("detectability", &json(0, &["detectability"]));
    valid(
        "compensate",
        &json(0, &["compensate", "--machine", "cal.json"]),
    );
    let check = [
        "check",
        "--machine",
        "cal.json",
        "--data",
        &data,
        "--history",
        "h.jsonl",
    ];
    valid("check", &json(0, &check));
    valid(
        "check-history",
        &std::fs::read_to_string(d.join("h.jsonl")).unwrap(),
    );
    valid(
        "plan",
        &json(0, &["plan", "--instrument", "touch", "--k", "30"]),
    );
    valid("effects", &json(0, &["effects"]));
    let fleet = [
        "fleet",
        "--data",
        &b1,
        "--data",
        &b2,
        "--data",
        &b3,
        "--write-prior",
        "prior.json",
    ];
    valid("fleet", &json(0, &fleet));
    valid(
        "prior",
        &std::fs::read_to_string(d.join("prior.json")).unwrap(),
    );
    valid(
        "export",
        &json(0, &["export", "--machine", "dep.json", "--out", "ex"]),
    );
    valid(
        "export-summary",
        &std::fs::read_to_string(d.join("ex/export.json")).unwrap(),
    );
    valid(
        "report",
        &json(
            0,
            &["report", "--machine", "cal.json", "--out", "page.html"],
        ),
    );
    std::fs::remove_dir_all(&dir).ok();
}
