//! A new user's program, from the docs alone: load a machine, identify it
//! from a campaign, write the calibrated file, diagnose and deploy a
//! campaign with a hidden leg lead, check the machine, command it by
//! inverse kinematics, and handle the errors a program meets.
//!
//! The campaigns are the repository's fixtures: `fixtures/data/
//! table2-grid-seed1.csv` (the paper's Table 2 errors) and
//! `fixtures/compat/lead.csv`, which `fixtures/compat/make.sh` simulates
//! with leg leads of (60, -40, 60) ppm: the expectations below come from
//! those simulator inputs, not from the library.

use std::path::{Path, PathBuf};

use tricept_ident::calibrate::{CalibrateRequest, calibrate};
use tricept_ident::check::{CheckRequest, check};
use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
use tricept_ident::kinematics::{Machine, Vector3};
use tricept_ident::{EXIT_INADEQUATE, EXIT_INPUT, EXIT_OK, ErrorCause, MachineInput, WriteOptions};

/// The simulated leads of `fixtures/compat/lead.csv`, ppm.
const LEAD_PPM: [f64; 3] = [60.0, -40.0, 60.0];

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tricept-seven-steps-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn the_seven_steps_of_a_downstream_program() -> Result<(), Box<dyn std::error::Error>> {
    let dir = scratch();
    let grid = fixture("data/table2-grid-seed1.csv");

    // 1. Load: the paper's machine, and the same from its file.
    let nominal = Machine::paper();
    assert_eq!(
        Machine::load(fixture("machines/tricept-paper.json"))?,
        nominal
    );

    // 2. Identify: trusted only with exit code 0.
    let calibration = calibrate(CalibrateRequest::new(&grid))?;
    assert_eq!(
        calibration.exit_code(),
        EXIT_OK,
        "{:?}",
        calibration.warnings()
    );

    // 3. Write the calibrated machine file, and read it back: the same
    // machine to command.
    let calibrated = dir.join("calibrated.json");
    calibration.write_machine(&calibrated, WriteOptions::default())?;
    let target = Vector3::new(0.0, 0.0, 750.0);
    let from_file = Machine::load(&calibrated)?.inverse(&target)?.legs_mm;
    assert_eq!(
        from_file,
        calibration.identified().inverse(&target)?.legs_mm
    );

    // 4. Diagnose a campaign with a hidden effect, and deploy what it
    // finds into a machine file.
    let lead = fixture("compat/lead.csv");
    let result = diagnose(DiagnoseRequest::new(&lead).machine(MachineInput::default()))?;
    assert_eq!(result.exit_code(), EXIT_OK);
    let deployed_file = dir.join("deployed.json");
    result.write_machine(&deployed_file, WriteOptions::default())?;
    let deployed = Machine::load(&deployed_file)?;
    for (found, simulated) in deployed.leg_effects().lead_ppm.iter().zip(LEAD_PPM) {
        assert!(
            (found - simulated).abs() < 10.0,
            "{found} ppm, simulated {simulated}"
        );
    }

    // 5. Check the calibrated machine against a campaign: unchanged.
    let checked = check(CheckRequest::new(&calibrated, &grid))?;
    assert_eq!(checked.exit_code(), EXIT_OK);

    // 6. Inverse kinematics of the deployed machine: its leads applied (a
    // leg that grows by lead 1e-6 q needs a command shorter by that).
    let q = deployed.inverse(&target)?.legs_mm;
    let q_nominal = nominal.inverse(&target)?.legs_mm;
    for i in 0..3 {
        let lead_mm = LEAD_PPM[i] * 1e-6 * q_nominal[i];
        assert!(lead_mm.abs() > 0.03);
        // The geometric errors move the commands by tenths of a mm; the
        // lead's part is the deployed machine against its own geometry.
        let geometric = deployed.geometry().inverse(&target)?.legs_mm[i];
        assert!(
            ((geometric - q[i]) - lead_mm).abs() < 0.2 * lead_mm.abs(),
            "leg {}",
            i + 1
        );
    }

    // 7. Errors a program matches: a missing file, an edited calibrated
    // file, a write refused because the result is not to be trusted.
    let missing = Machine::load(dir.join("no-such.json")).unwrap_err();
    assert!(
        matches!(missing.cause(), ErrorCause::NotFound { .. }),
        "{missing}"
    );
    assert_eq!(missing.exit_code(), EXIT_INPUT);
    let text = std::fs::read_to_string(&calibrated)?;
    let edited = dir.join("edited.json");
    std::fs::write(
        &edited,
        text.replacen("\"name\": \"", "\"name\": \"edited ", 1),
    )?;
    let e = Machine::load(&edited).unwrap_err();
    assert!(
        matches!(e.cause(), ErrorCause::SealBroken { fields } if fields == ["name"]),
        "{e}"
    );
    let untrusted = calibrate(CalibrateRequest::new(fixture(
        "data/diagnose-hidden-effect.csv",
    )))?;
    assert_eq!(untrusted.exit_code(), EXIT_INADEQUATE);
    let e = untrusted
        .write_machine(&dir.join("untrusted.json"), WriteOptions::default())
        .unwrap_err();
    assert_eq!(e.cause(), ErrorCause::RefusedWrite);
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}
