//! Errors a program can match: each failure a user meets (a missing file,
//! a file that does not parse, a newer format, an edited calibrated file,
//! a refused write) has its [`ErrorCause`], with the file, the line and
//! column or the edited fields, and the library error under it as its
//! `source()`.

use std::error::Error as _;

use tricept_ident::calibrate::{CalibrateRequest, calibrate};
use tricept_ident::kinematics::Machine;
use tricept_ident::{EXIT_INADEQUATE, EXIT_INPUT, ErrorCause};

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
