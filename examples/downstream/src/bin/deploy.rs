//! A downstream program that diagnoses measured data and deploys what the
//! diagnosis found, with `tricept-diagnose` as a library: it refuses to go
//! on unless the final model explains the data and names no generic term
//! (whose physics a machine file cannot carry), then deploys the model
//! (`tricept_diagnose::deploy`: each effect where the registry says it
//! goes) and prints the calibrated leg commands for a few targets and the
//! controller parameters of the dynamic effects.
//!
//! ```sh
//! cargo run -p tricept-example-downstream --bin deploy -- fixtures/data/diagnose-hidden-effect.csv
//! ```

use std::process::ExitCode;

use nalgebra::Vector3;
use tricept_diagnose::{CauseKind, DiagnoseOptions, deploy, diagnose};
use tricept_ident::{ExtendedMachine, Machine, read_path};

fn main() -> ExitCode {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/data/diagnose-hidden-effect.csv"
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
    let nominal = Machine::paper();
    let d = diagnose(&nominal, &data, &DiagnoseOptions::for_machine(&nominal))?;
    for c in &d.causes {
        println!("{}: {}", c.effect, c.description);
    }
    if !d.final_adequate {
        return Err("the final model does not explain the data (see the report)".into());
    }
    if d.causes.iter().any(|c| c.kind == CauseKind::Generic) {
        return Err("a generic term is named: its physics is not in a machine file".into());
    }
    let deployed = deploy(&nominal, None, &data, &d)?;
    if let Some(c) = &deployed.controller {
        println!("controller: {c:?}");
    }
    let calibrated = ExtendedMachine::new(deployed.machine);
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
