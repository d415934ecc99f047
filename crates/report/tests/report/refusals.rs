//! Bad inputs, as everywhere (exit code 2, naming which): an edited
//! machine file, a file without a calibration, a campaign that is not the
//! calibration's, a history of another calibration, an export of another
//! calibration, an export folder that holds none.

use serde_json::Value;
use tricept_ident::EXIT_INPUT;

use crate::browser::PITCH;
use crate::support::{
    Dir, campaign, check_into, export_of, fixture, page, pitch_machine, read_json, table2_machine,
};

#[test]
fn inputs_of_another_calibration_are_refused_naming_the_file() {
    let dir = Dir::new("refusals");
    let table2 = table2_machine(&dir);
    let pitch = pitch_machine(&dir);
    let out = dir.join("page.html");
    let refused = |e: tricept_ident::Error, names: &[&str]| {
        assert_eq!(e.exit_code(), EXIT_INPUT, "{e}");
        for n in names {
            assert!(e.message().contains(n), "`{n}` not named: {e}");
        }
        assert!(!out.exists(), "a page was written: {e}");
    };

    // An edited machine file: the seal refuses it on load, naming the field.
    let mut edited = read_json(&table2);
    let sd = &mut edited["calibration"]["std_dev_mm"]["dq1"];
    *sd = Value::from(sd.as_f64().unwrap() * 2.0);
    let edited_file = dir.join("edited.json");
    std::fs::write(&edited_file, edited.to_string()).unwrap();
    let e = page(&edited_file, None, None, None, &out).unwrap_err();
    refused(e, &["edited.json", "calibration.std_dev_mm"]);

    // A plain description: nothing to report.
    let plain = fixture("fixtures/machines/tricept-paper.json");
    refused(
        page(&plain, None, None, None, &out).unwrap_err(),
        &["tricept-paper.json", "calibration"],
    );

    // Another campaign than the calibration's.
    let other = fixture("fixtures/data/diagnose-pitch.csv");
    refused(
        page(&table2, Some(&other), None, None, &out).unwrap_err(),
        &["diagnose-pitch.csv", "SHA-256", "table2-grid-seed1.csv"],
    );

    // A history of another calibration: its first check is named.
    let history = dir.join("pitch-checks.jsonl");
    let truth = tricept_ident::advanced::TrueErrors::Random {
        magnitude_mm: 0.25,
        seed: 4,
    };
    let day = campaign(&dir, "day.csv", truth, &[PITCH], 3, 1.0);
    check_into(&pitch, &day, &history);
    refused(
        page(&table2, None, Some(&history), None, &out).unwrap_err(),
        &["pitch-checks.jsonl", "check 1", "another calibration"],
    );
    // ... and one whose later check is of another calibration.
    let mixed = dir.join("mixed.jsonl");
    let day2 = campaign(
        &dir,
        "day2.csv",
        tricept_ident::advanced::TrueErrors::Table2,
        &[],
        5,
        1.0,
    );
    check_into(&table2, &day2, &mixed);
    // `check` itself refuses to append a check of another calibration, so
    // the mixed file is made as a careless concatenation would make it.
    let joined = [
        std::fs::read_to_string(&mixed).unwrap(),
        std::fs::read_to_string(&history).unwrap(),
    ]
    .concat();
    std::fs::write(&mixed, joined).unwrap();
    refused(
        page(&table2, None, Some(&mixed), None, &out).unwrap_err(),
        &["mixed.jsonl", "check 2"],
    );

    // An export of another calibration.
    let cnc = export_of(&pitch, &dir, "cnc");
    refused(
        page(&table2, None, None, Some(&cnc), &out).unwrap_err(),
        &["export.json", "another calibration"],
    );
    // A folder that holds no export.
    refused(
        page(&table2, None, None, Some(&dir.join("nothing")), &out).unwrap_err(),
        &["export.json"],
    );

    // The same inputs of its own calibration make a page.
    let own = export_of(&table2, &dir, "cnc2");
    let table2_history = dir.join("t2.jsonl");
    check_into(&table2, &day2, &table2_history);
    let data = fixture("fixtures/data/table2-grid-seed1.csv");
    page(
        &table2,
        Some(&data),
        Some(&table2_history),
        Some(&own),
        &out,
    )
    .unwrap();
    assert!(out.is_file());
}

#[test]
fn lines_and_exports_written_before_they_named_a_calibration_are_read_with_a_caution() {
    let dir = Dir::new("unnamed");
    let table2 = table2_machine(&dir);
    let history = dir.join("checks.jsonl");
    let day = campaign(
        &dir,
        "day.csv",
        tricept_ident::advanced::TrueErrors::Table2,
        &[],
        7,
        1.0,
    );
    check_into(&table2, &day, &history);
    // As a line of a history written before lines named their calibration.
    let line: Value =
        serde_json::from_str(std::fs::read_to_string(&history).unwrap().trim()).unwrap();
    let mut old = line.clone();
    old.as_object_mut()
        .unwrap()
        .remove("calibration_digest")
        .unwrap();
    std::fs::write(&history, format!("{old}\n{line}\n")).unwrap();
    let cnc = export_of(&table2, &dir, "cnc");
    let summary = cnc.join("export.json");
    let mut s = read_json(&summary);
    s.as_object_mut()
        .unwrap()
        .remove("calibration_digest")
        .unwrap();
    std::fs::write(&summary, s.to_string()).unwrap();
    let out = dir.join("page.html");
    let r = page(&table2, None, Some(&history), Some(&cnc), &out).unwrap();
    let says = crate::support::reasons(&r);
    assert!(
        says.iter()
            .any(|s| s.contains("history's checks from this one on name no calibration")),
        "{says:?}"
    );
    assert!(
        says.iter()
            .any(|s| s.contains("the export names no calibration")),
        "{says:?}"
    );
    assert!(r.verdict().level >= tricept_ident::report::Level::Caution);
    // The reason points at the first unnamed check.
    let html = std::fs::read_to_string(&out).unwrap();
    assert!(html.contains("data-src=\"history\" data-path=\"/0/time\""));
}
