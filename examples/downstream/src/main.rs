//! A downstream program built on `tricept-ident` alone: it reads a
//! measured-data CSV, identifies the machine's geometric errors, refuses
//! to go on unless the fit converged and the model explains the data, and
//! prints the calibrated leg commands for a few targets.
//!
//! ```sh
//! cargo run -p tricept-example-downstream -- fixtures/data/table2-grid-seed1.csv
//! ```

use std::process::ExitCode;

use tricept_ident::nalgebra::Vector3;
use tricept_ident::{
    ExtendedMachine, GeometricModel, IdentifyOptions, Machine, ParameterSet, identify_robust,
    read_path,
};

fn main() -> ExitCode {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/data/table2-grid-seed1.csv"
        )
        .to_string()
    });
    match run(&path) {
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
