//! A downstream program that diagnoses measured data and deploys what the
//! diagnosis found, with `tricept-diagnose` as a library: it refuses to go
//! on unless the final model explains the data and names no generic term
//! (whose physics a machine file cannot carry), then deploys the model
//! (`tricept_diagnose::deploy`: each effect where the registry says it
//! goes) and prints the deployed leg effects, the controller parameters of
//! the dynamic effects and the calibrated leg commands at the centre of the
//! workspace.
//!
//! ```sh
//! cargo run -p tricept-example-deploy -- fixtures/data/diagnose-hidden-effect.csv
//! ```

use tricept_diagnose::{CauseKind, DiagnoseOptions, deploy, diagnose};
use tricept_ident::nalgebra::Vector3;
use tricept_ident::{ExtendedMachine, Machine, read_path};

/// The data file when none is given: a campaign with a hidden compliance.
const DEFAULT_DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../fixtures/data/diagnose-hidden-effect.csv"
);

/// Errors end the program with their message and exit code 1.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1);
    let path = path.as_deref().unwrap_or(DEFAULT_DATA);
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
    println!("leg effects: {:?}", deployed.machine.leg_effects);
    let calibrated = ExtendedMachine::new(deployed.machine);
    let target = Vector3::new(0.0, 0.0, 750.0);
    let q = calibrated.inverse(&target)?.legs_mm;
    let q_nominal = nominal.inverse(&target)?.legs_mm;
    println!("leg commands at the workspace centre, mm: {q:?} (nominal {q_nominal:?})");
    Ok(())
}
