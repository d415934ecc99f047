//! A downstream program built on `tricept-ident` alone, one function per
//! step of the door's workflows: it calibrates the machine from a
//! measured-data CSV (`tricept_ident::calibrate`, what `tricept identify`
//! runs), refuses to go on unless the verdict says the calibration can be
//! trusted, writes the calibrated machine file by the one write rule, and
//! prints the calibrated leg commands for a few targets.
//!
//! ```sh
//! cargo run -p tricept-example-downstream -- fixtures/data/table2-grid-seed1.csv [calibrated.json]
//! ```

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use tricept_ident::nalgebra::Vector3;
use tricept_ident::{CalibrateRequest, Calibration, Data, Error, ExtendedMachine, calibrate};

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
    match run(&data, &out) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

fn run(data: &Path, out: &Path) -> Result<(), Error> {
    let mut calibration = identify(data)?;
    write_machine(&mut calibration, out)?;
    command(&calibration)
}

/// Step 1: calibrate from the UP limb's sensors and judge the verdict.
fn identify(data: &Path) -> Result<Calibration, Error> {
    let calibration = calibrate(&CalibrateRequest::new(Data::File(data.to_path_buf())))?;
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
                calibration.reason()
            ),
        ));
    }
    Ok(calibration)
}

/// Step 2: write the calibrated machine file (refused for a fit that is
/// not to be trusted).
fn write_machine(calibration: &mut Calibration, out: &Path) -> Result<(), Error> {
    let written = calibration.write_machine(out, false)?;
    println!("wrote {}", written.path().display());
    Ok(())
}

/// Step 3: command the calibrated machine.
fn command(calibration: &Calibration) -> Result<(), Error> {
    let calibrated = ExtendedMachine::new(calibration.identified());
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
