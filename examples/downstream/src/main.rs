//! A downstream program built on `tricept-ident` alone: it reads a
//! measured-data CSV, identifies the machine's geometric errors, refuses
//! to go on unless the fit converged and the model explains the data, and
//! prints the calibrated leg commands for a few targets; then it diagnoses
//! the same data, deploys the final model and writes it as a calibrated
//! machine file, and checks the data against that file (has the machine
//! changed since its calibration?).
//!
//! ```sh
//! cargo run -p tricept-example-downstream -- fixtures/data/table2-grid-seed1.csv
//! ```

use std::path::Path;
use std::process::ExitCode;

use tricept_ident::nalgebra::Vector3;
use tricept_ident::{
    CheckRequest, DiagnoseRequest, EXIT_OK, ExtendedMachine, GeometricModel, IdentifyOptions,
    Machine, ParameterSet, SensorNoise, check, diagnose, identify_robust, load_machine, read_path,
};

fn main() -> ExitCode {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/data/table2-grid-seed1.csv"
        )
        .to_string()
    });
    let calibrated =
        std::env::temp_dir().join(format!("tricept-downstream-{}.json", std::process::id()));
    let steps = run(&path)
        .and_then(|()| diagnose_and_deploy(&path, &calibrated))
        .and_then(|()| check_against(&calibrated, &path));
    std::fs::remove_file(&calibrated).ok();
    match steps {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(path: &str) -> Result<(), Box<dyn std::error::Error>> {
    let data = read_path(path.as_ref())?;
    let machine = Machine::paper();
    let model = GeometricModel::new(machine.clone(), ParameterSet::paper15());
    let (id, rejected) = identify_robust(&model, &data, &IdentifyOptions::for_machine(&machine))?;
    let verdict = id.verdict();
    for w in &verdict.warnings {
        eprintln!("warning: {w}");
    }
    if !(verdict.converged && verdict.adequate) {
        return Err("the calibration cannot be trusted (see the warnings)".into());
    }
    println!(
        "{}: {} poses, {} rejected, chi2/dof {:.3}",
        path,
        id.residuals.len(),
        rejected.len(),
        id.stats.reduced_chi_square
    );
    let calibrated = ExtendedMachine::new(model.machine_at(&id.estimate));
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

/// Diagnoses the data (does the geometric model explain them, and if not,
/// which effect does), refuses to go on unless the final model explains
/// them, deploys it (the calibrated leg commands at the centre) and writes
/// it to `out` as a calibrated machine file.
fn diagnose_and_deploy(path: &str, out: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let nominal = load_machine(None, &SensorNoise::default())?;
    let result = diagnose(DiagnoseRequest::new(nominal, path))?;
    println!("diagnosis: {:?}", result.diagnosis().verdict);
    if let Some(why) = result.exit_reason() {
        return Err(why.into());
    }
    let deployed = result.deploy()?;
    let q = ExtendedMachine::new(deployed.machine)
        .inverse(&Vector3::new(0.0, 0.0, 750.0))?
        .legs_mm;
    println!("deployed: leg commands at the centre {q:?} mm");
    if let Some(warning) = result.write_machine(out, false)? {
        eprintln!("warning: {warning}");
    }
    println!("wrote {}", out.display());
    Ok(())
}

/// Checks the data against the calibrated machine file `calibrated`: has
/// the machine changed since its calibration?
fn check_against(calibrated: &Path, path: &str) -> Result<(), Box<dyn std::error::Error>> {
    let machine = load_machine(Some(calibrated), &SensorNoise::default())?;
    let result = check(CheckRequest::new(machine, path))?;
    print!("{}", result.to_text());
    match result.exit_reason() {
        None if result.exit_code() == EXIT_OK => Ok(()),
        why => Err(why.unwrap_or_default().into()),
    }
}
