//! A downstream program built on `tricept-ident` alone, one function per
//! step of the door's workflows: it calibrates the machine from a
//! measured-data CSV (`tricept_ident::calibrate`, what `tricept identify`
//! runs), refuses to go on unless the verdict says the calibration can be
//! trusted, writes the calibrated machine file by the one write rule, and
//! prints the calibrated leg commands for a few targets; then it diagnoses
//! the same data, deploys the final model and writes it as a calibrated
//! machine file (what `tricept diagnose --write-machine` runs), and checks
//! the data against the calibration (what `tricept check` runs: has the
//! machine changed since?).
//!
//! ```sh
//! cargo run -p tricept-example-downstream -- fixtures/data/table2-grid-seed1.csv [calibrated.json]
//! ```

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use tricept_ident::calibrate::{CalibrateRequest, Calibration, calibrate};
use tricept_ident::check::{CheckRequest, check};
use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
use tricept_ident::kinematics::{Machine, Vector3};
use tricept_ident::{EXIT_OK, Error, MachineInput, WriteOptions};

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let data = args.next().map_or_else(
        || {
            PathBuf::from(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../fixtures/data/table2-grid-seed1.csv"
            ))
        },
        PathBuf::from,
    );
    let out = args.next().map_or_else(
        || std::env::temp_dir().join("tricept-downstream-calibrated.json"),
        PathBuf::from,
    );
    let deployed = out.with_extension("deployed.json");
    let steps = run(&data, &out)
        .and_then(|()| diagnose_and_deploy(&data, &deployed))
        .and_then(|()| check_against(&out, &data));
    match steps {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.downcast_ref::<Error>().map_or(1, Error::exit_code))
        }
    }
}

fn run(data: &Path, out: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let calibration = identify(data)?;
    write_machine(&calibration, out)?;
    Ok(command(&calibration)?)
}

/// Step 1: calibrate from the UP limb's sensors and judge the verdict.
fn identify(data: &Path) -> Result<Calibration, Error> {
    let calibration = calibrate(CalibrateRequest::new(data))?;
    for w in calibration.warnings() {
        eprintln!("warning: {w}");
    }
    println!(
        "{}: exit code {}, {} parameters",
        data.display(),
        calibration.exit_code(),
        calibration.estimates().len()
    );
    if calibration.exit_code() != 0 {
        return Err(Error::new(
            tricept_ident::ErrorKind::of_exit_code(calibration.exit_code()),
            format!(
                "the calibration cannot be trusted: {}",
                calibration.reason().unwrap_or_default()
            ),
        ));
    }
    Ok(calibration)
}

/// Step 2: write the calibrated machine file (refused for a fit that is
/// not to be trusted).
fn write_machine(calibration: &Calibration, out: &Path) -> Result<(), Error> {
    let written = calibration.write_machine(out, WriteOptions::default())?;
    println!("wrote {}", written.path().display());
    Ok(())
}

/// Step 3: command the calibrated machine.
fn command(calibration: &Calibration) -> Result<(), Error> {
    let calibrated = calibration.identified();
    println!("x,y,z,q1,q2,q3");
    for r in [
        Vector3::new(0.0, 0.0, 750.0),
        Vector3::new(200.0, -100.0, 700.0),
    ] {
        let q = calibrated.inverse(&r)?.legs_mm;
        println!("{},{},{},{},{},{}", r.x, r.y, r.z, q[0], q[1], q[2]);
    }
    Ok(())
}

/// Step 4: diagnoses the data (does the geometric model explain them, and if not,
/// which effect does), refuses to go on unless the final model explains
/// them, deploys it (the calibrated leg commands at the centre) and writes
/// it to `out` as a calibrated machine file.
fn diagnose_and_deploy(path: &Path, out: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let nominal = MachineInput::default();
    let result = diagnose(DiagnoseRequest::new(path.to_path_buf()).machine(nominal))?;
    println!("diagnosis: {:?}", result.diagnosis().verdict);
    if let Some(why) = result.reason() {
        return Err(why.into());
    }
    let deployed = result.deploy()?;
    let q = Machine::from(deployed)
        .inverse(&Vector3::new(0.0, 0.0, 750.0))?
        .legs_mm;
    println!("deployed: leg commands at the centre {q:?} mm");
    let written = result.write_machine(out, WriteOptions::default())?;
    println!("wrote {}", written.path().display());
    Ok(())
}

/// Step 5: checks the data against the calibrated machine file `calibrated`: has
/// the machine changed since its calibration?
fn check_against(calibrated: &Path, path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let machine = MachineInput::from(calibrated);
    let result = check(CheckRequest::new(machine, path.to_path_buf()))?;
    print!("{}", result.report());
    match result.reason() {
        None if result.exit_code() == EXIT_OK => Ok(()),
        why => Err(why.unwrap_or_default().into()),
    }
}
