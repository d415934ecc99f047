//! A complete self-calibration, as a downstream user would write it:
//! load logged data, identify, read the report, compensate.
//!
//! ```text
//! cargo run -p tricept-engine --example calibrate                     # the committed fixture
//! cargo run -p tricept-engine --example calibrate -- data.csv machine.json
//! ```

use std::path::PathBuf;

use nalgebra::Vector3;
use tricept_engine::{
    IdentifyOptions, compensate::corrected_commands, identify, model::GeometricModel,
};
use tricept_kinematics::{Machine, MachineDescription};
use tricept_model::{ParameterSet, volumetric::volumetric_errors};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let data_path = args
        .first()
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("fixtures/data/table2-grid-seed1.csv"));
    // 1. The nominal machine: a description file, or the paper's machine.
    let nominal: Machine = match args.get(1) {
        Some(path) => MachineDescription::from_file(path.as_ref())?.build()?,
        None => Machine::paper(),
    };

    // 2. The logged data (q1,q2,q3,phi,theta,s per pose). Errors name the
    //    file, line and column.
    let data = tricept_data::read_path(&data_path)?;
    println!("{} poses from {}", data.poses.len(), data_path.display());

    // 3. Identify the paper's 15 parameters; sensor noise from the machine.
    let model = GeometricModel::new(nominal.clone(), ParameterSet::paper15());
    let id = identify(&model, &data, &IdentifyOptions::for_machine(&nominal))?;

    // 4. Read the report before trusting the numbers.
    println!("{}", id.report.to_text());
    println!(
        "fit: chi2/dof = {:.3} ({} dof) -- near 1 means the model explains the data",
        id.stats.reduced_chi_square, id.stats.dof
    );
    for ((name, value), sd) in id.names.iter().zip(&id.estimate).zip(&id.std_dev) {
        match sd {
            Some(sd) => println!("{name:>6} = {value:+.4} mm  (sd {sd:.4})"),
            None => println!("{name:>6} = {value:+.4} mm  (not identifiable: held at nominal)"),
        }
    }

    // 5. Compensate: command through the identified machine's IK.
    let identified = model.machine_at(&id.estimate);
    let targets = vec![
        Vector3::new(0.0, 0.0, 750.0),
        Vector3::new(250.0, -100.0, 700.0),
        Vector3::new(-300.0, 200.0, 820.0),
    ];
    for (r, q) in targets
        .iter()
        .zip(corrected_commands(&identified, &targets)?)
    {
        let nominal_q = nominal.inverse(r)?.legs_mm;
        println!(
            "target {:?}: corrected commands {:.4?} (nominal {:.4?})",
            [r.x, r.y, r.z],
            q,
            nominal_q
        );
    }
    // What the compensation changes over the middle plane, as the model sees it.
    let plane = nominal
        .workspace
        .disc_grid(nominal.workspace.mid_plane_z_mm(), 50.0);
    let shift = volumetric_errors(&nominal, &identified, &plane)?.stats();
    println!(
        "compensation moves the platform by {:.3}..{:.3} mm (mean {:.3}) over the middle plane",
        shift.min_mm, shift.max_mm, shift.mean_mm
    );
    Ok(())
}
