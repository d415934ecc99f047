//! A downstream program that diagnoses measured data and deploys what the
//! diagnosis found, with `tricept-ident` as its only dependency: it
//! refuses to go on unless the final model explains the data, then deploys
//! the model (`DiagnoseResult::deploy`: each term worth deploying where the
//! registry says it goes, a generic leg error as per-leg compensation
//! tables) and prints what it applies and what it only records, the
//! controller parameters of the dynamic effects and the calibrated leg
//! commands at the centre of the workspace.
//!
//! ```sh
//! cargo run -p tricept-example-deploy -- fixtures/data/diagnose-hidden-effect.csv
//! ```

use tricept_ident::MachineInput;
use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
use tricept_ident::kinematics::{Machine, Vector3};

/// The data file when none is given: a campaign with a hidden compliance.
const DEFAULT_DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../fixtures/data/diagnose-hidden-effect.csv"
);

/// Errors end the program with their message and exit code 1.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1);
    let path = path.as_deref().unwrap_or(DEFAULT_DATA);
    let loaded = MachineInput::default().load()?;
    let nominal = loaded.commanding();
    let result = diagnose(DiagnoseRequest::new(path).machine(loaded))?;
    for c in &result.diagnosis().causes {
        println!("{}: {}", c.effect, c.description);
    }
    if let Some(why) = result.reason() {
        return Err(why.into());
    }
    let deployed = result.deploy()?;
    for line in &deployed.applied {
        println!("applies: {line}");
    }
    for line in &deployed.recorded {
        println!("records: {line}");
    }
    if let Some(c) = &deployed.controller {
        println!("controller: {c:?}");
    }
    let e = &deployed.geometry.leg_effects;
    println!(
        "leg effects: lead {:?} ppm, compliance {} um/kN at 1 m, {} compensation tables",
        e.lead_ppm,
        e.compliance_um_per_kn_at_1m,
        e.tables.len()
    );
    let calibrated = Machine::from(deployed);
    let target = Vector3::new(0.0, 0.0, 750.0);
    let q = calibrated.inverse(&target)?.legs_mm;
    let q_nominal = nominal.inverse(&target)?.legs_mm;
    println!("leg commands at the workspace centre, mm: {q:?} (nominal {q_nominal:?})");
    Ok(())
}
