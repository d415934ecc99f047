//! Errors a program can match: each failure a user meets (a missing file,
//! a file that does not parse, a newer format, an edited calibrated file,
//! a refused write) has its [`ErrorCause`], with the file, the line and
//! column or the edited fields, and the library error under it as its
//! `source()`; an error about a request setting carries the setting and
//! names it by its field, never by a command-line flag.

use std::error::Error as _;

use tricept_ident::calibrate::{CalibrateRequest, calibrate};
use tricept_ident::export::{Controller, ExportError, ExportOptions, ExportRequest, export};
use tricept_ident::kinematics::Machine;
use tricept_ident::{EXIT_INADEQUATE, EXIT_INPUT, ErrorCause, ErrorKind, Setting, WriteOptions};

fn fixture(name: &str) -> String {
    format!("{}/../../fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "tricept-ident-errors-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn a_missing_file_and_a_file_that_does_not_parse_are_told_apart() {
    let e = Machine::load("no/such/machine.json").unwrap_err();
    assert_eq!(
        e.cause(),
        ErrorCause::NotFound {
            path: "no/such/machine.json".into()
        }
    );
    assert_eq!(e.exit_code(), EXIT_INPUT);
    let dir = scratch("parse");
    let file = dir.join("m.json");
    // Line 3, column 15: the value of a key is not JSON.
    std::fs::write(&file, "{\n  \"name\": \"x\",\n  \"notes\": oops\n}\n").unwrap();
    let e = Machine::load(&file).unwrap_err();
    assert_eq!(
        e.cause(),
        ErrorCause::Parse {
            line: Some(3),
            column: Some(12)
        },
        "{e}"
    );
    assert!(e.to_string().contains("line 3, column 12"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_newer_format_and_an_edited_calibrated_file_are_named() {
    let dir = scratch("seal");
    let text = std::fs::read_to_string(fixture("compat/machine-calibrated.json")).unwrap();
    let newer = dir.join("newer.json");
    std::fs::write(
        &newer,
        text.replacen("\"format_version\": 1", "\"format_version\": 3", 1),
    )
    .unwrap();
    let e = Machine::load(&newer).unwrap_err();
    assert_eq!(
        e.cause(),
        ErrorCause::NewerFormat {
            found: 3,
            supported: 1
        },
        "{e}"
    );
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["leg_offsets_mm"][1] = (v["leg_offsets_mm"][1].as_f64().unwrap() + 0.01).into();
    let edited = dir.join("edited.json");
    std::fs::write(&edited, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let e = Machine::load(&edited).unwrap_err();
    match e.cause() {
        ErrorCause::SealBroken { fields } => assert_eq!(fields, ["leg_offsets_mm"], "{e}"),
        other => panic!("{other:?}: {e}"),
    }
    assert_eq!(e.exit_code(), EXIT_INPUT);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_write_of_an_untrusted_calibration_is_refused_as_such_with_its_source() {
    let dir = scratch("refused");
    // A hidden compliance the geometric model cannot explain: exit 3.
    let calibration = calibrate(CalibrateRequest::new(
        fixture("data/diagnose-hidden-effect.csv").as_str(),
    ))
    .unwrap();
    assert_eq!(calibration.exit_code(), EXIT_INADEQUATE);
    let e = calibration
        .write_machine(
            &dir.join("cal.json"),
            tricept_ident::WriteOptions::default(),
        )
        .unwrap_err();
    assert_eq!(e.cause(), ErrorCause::RefusedWrite, "{e}");
    assert_eq!(e.exit_code(), EXIT_INADEQUATE);
    assert!(!dir.join("cal.json").exists());
    // A library error converted into the door's keeps it as its source.
    let inner = tricept_ident::kinematics::MachineDescription::from_json("{").unwrap_err();
    let e = tricept_ident::Error::from(inner);
    assert!(
        e.source().is_some_and(|s| s.to_string() == e.to_string()),
        "{e}"
    );
    assert!(
        matches!(e.cause(), ErrorCause::Parse { line: Some(1), .. }),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The chain of `source()`s under `e`, outermost first.
fn chain<'a>(
    e: &'a (dyn std::error::Error + 'static),
) -> Vec<&'a (dyn std::error::Error + 'static)> {
    let mut out = Vec::new();
    let mut next = e.source();
    while let Some(s) = next {
        out.push(s);
        next = s.source();
    }
    out
}

#[test]
fn a_missing_unreadable_or_malformed_machine_file_keeps_the_lower_error_as_its_source() {
    // Missing: the operating system's NotFound is at the end of the chain.
    let e = Machine::load("no/such/machine.json").unwrap_err();
    let io = chain(&e)
        .into_iter()
        .find_map(|s| s.downcast_ref::<std::io::Error>())
        .unwrap_or_else(|| panic!("no io::Error under {e}"));
    assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
    // A folder where a file is expected: unreadable, not missing.
    let dir = scratch("unreadable");
    let e = Machine::load(&dir).unwrap_err();
    let shown = dir.display().to_string();
    assert_eq!(e.cause(), ErrorCause::Unreadable { path: shown }, "{e}");
    assert!(!chain(&e).is_empty(), "{e}");
    // Not JSON at line 2, column 11 (the `x` after `"name": `): the
    // parser's own error is under the door's, at the same place.
    let file = dir.join("m.json");
    std::fs::write(&file, "{\n  \"name\": x\n}\n").unwrap();
    let e = Machine::load(&file).unwrap_err();
    assert_eq!(
        e.cause(),
        ErrorCause::Parse {
            line: Some(2),
            column: Some(11)
        },
        "{e}"
    );
    let json = chain(&e)
        .into_iter()
        .find_map(|s| s.downcast_ref::<serde_json::Error>())
        .unwrap_or_else(|| panic!("no serde_json::Error under {e}"));
    assert_eq!((json.line(), json.column()), (2, 11));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_broken_seal_keeps_the_record_s_error_as_its_source() {
    let dir = scratch("seal-source");
    let text = std::fs::read_to_string(fixture("compat/machine-calibrated.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["notes"] = "edited by hand".into();
    let edited = dir.join("edited.json");
    std::fs::write(&edited, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let e = Machine::load(&edited).unwrap_err();
    match e.cause() {
        ErrorCause::SealBroken { fields } => assert_eq!(fields, ["notes"], "{e}"),
        other => panic!("{other:?}: {e}"),
    }
    let under = e.source().unwrap_or_else(|| panic!("no source under {e}"));
    assert!(under.to_string().contains("notes"), "{under}");
    assert!(e.to_string().ends_with(&under.to_string()), "{e} / {under}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_campaign_that_is_missing_or_does_not_parse_is_told_apart() {
    let dir = scratch("data");
    let missing = dir.join("no-such.csv");
    let e = calibrate(CalibrateRequest::new(missing.as_path())).unwrap_err();
    assert_eq!(
        e.cause(),
        ErrorCause::NotFound {
            path: missing.display().to_string()
        },
        "{e}"
    );
    assert_eq!(e.exit_code(), EXIT_INPUT);
    // One bad reading: the fixture with `phi` of its third pose unreadable.
    let text = std::fs::read_to_string(fixture("data/diagnose-hidden-effect.csv")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let header = lines.iter().position(|l| l.starts_with("q1,")).unwrap();
    let bad_line = header + 3; // 0-based: the third pose after the header
    let mut edited: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    let mut fields: Vec<&str> = lines[bad_line].split(',').collect();
    fields[3] = "0.3x";
    edited[bad_line] = fields.join(",");
    let file = dir.join("bad.csv");
    std::fs::write(&file, edited.join("\n") + "\n").unwrap();
    let e = calibrate(CalibrateRequest::new(file.as_path())).unwrap_err();
    assert_eq!(
        e.cause(),
        ErrorCause::Parse {
            line: Some(bad_line as u64 + 1),
            column: None
        },
        "{e}"
    );
    assert!(e.to_string().contains("phi"), "{e}");
    assert!(e.source().is_some(), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_error_about_a_setting_names_the_request_field_and_carries_it() {
    let mut request = CalibrateRequest::new(fixture("data/diagnose-hidden-effect.csv").as_str());
    request.tolerance_mm = 20.0;
    let e = calibrate(request).unwrap_err();
    assert_eq!(e.setting(), Some(Setting::ToleranceMm));
    assert_eq!(e.cause(), ErrorCause::Invalid);
    assert!(e.message().starts_with("tolerance_mm: "), "{e}");
    assert!(e.message().ends_with("got 20"), "{e}");
    assert_eq!(
        e.message_naming(|s| if s == Setting::ToleranceMm {
            "TOL"
        } else {
            "?"
        }),
        e.message().replacen("tolerance_mm", "TOL", 1)
    );
    // A setting of a lower crate's options (the export's points per axis)
    // arrives named the same way, the export's error as its source.
    let dir = scratch("export-setting");
    let mut options = ExportOptions::new(Controller::Heidenhain);
    options.max_points = Some(2);
    let e = export(ExportRequest::new(
        fixture("compat/machine-calibrated.json").as_str(),
        options,
        dir.join("out"),
    ))
    .unwrap_err();
    assert_eq!(e.setting(), Some(Setting::MaxPoints), "{e}");
    assert!(e.message().starts_with("max_points: "), "{e}");
    assert!(
        e.source()
            .and_then(|s| s.downcast_ref::<ExportError>())
            .is_some(),
        "{e}"
    );
    assert!(!dir.join("out").exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_refused_write_says_whether_the_fit_was_inadequate_by_its_kind() {
    let dir = scratch("refused-kind");
    let calibration = calibrate(CalibrateRequest::new(
        fixture("data/diagnose-hidden-effect.csv").as_str(),
    ))
    .unwrap();
    let e = calibration
        .write_machine(&dir.join("cal.json"), WriteOptions::default())
        .unwrap_err();
    assert_eq!(e.cause(), ErrorCause::RefusedWrite, "{e}");
    assert_eq!(e.kind(), ErrorKind::Inadequate, "{e}");
    // The library names no flag: the CLI adds `--force`.
    assert!(!e.message().contains("--"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
