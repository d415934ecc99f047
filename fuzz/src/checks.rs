//! The properties the fuzz targets check, one function per target.
//!
//! Shared by the libFuzzer targets in `fuzz_targets/` and by the ordinary
//! regression test `crates/engine/tests/engine/fuzz_regressions.rs`, which replays
//! every file under `fuzz/seeds/` and `fuzz/regressions/` on each
//! `cargo test`. A crash input found by `cargo fuzz` is committed to
//! `fuzz/regressions/<target>/` once the bug is fixed.

use nalgebra::Vector3;
use tricept_engine::{IdentifyOptions, model::GeometricModel, robust::identify_robust};
use tricept_kinematics::{Machine, MachineDescription};
use tricept_model::ParameterSet;

/// The measured-data reader on arbitrary bytes: an error or a dataset,
/// never a panic; a dataset it accepts must round-trip through the writer.
pub fn csv_reader(bytes: &[u8]) {
    let Ok(data) = tricept_data::read_from(bytes, "fuzz.csv") else {
        return;
    };
    let mut out = Vec::new();
    tricept_data::write_to(&mut out, &data, &[]).unwrap();
    let again = tricept_data::read_from(out.as_slice(), "again.csv").unwrap();
    assert_eq!(again.poses.len(), data.poses.len());
    for (a, b) in data.poses.iter().zip(&again.poses) {
        assert_eq!(a.commands_mm, b.commands_mm);
        assert_eq!(a.readings, b.readings);
    }
}

/// Machine descriptions from arbitrary text: a validated machine or an
/// error; a machine it accepts must survive IK and FK at its workspace
/// centre, and FK from arbitrary leg lengths, without panicking.
pub fn machine_description(text: &str) {
    let Ok(description) = MachineDescription::from_json(text) else {
        return;
    };
    let Ok(machine) = description.build() else {
        return;
    };
    let centre = Vector3::new(0.0, 0.0, machine.workspace.mid_plane_z_mm());
    if let Ok(ik) = machine.inverse(&centre) {
        let _ = machine.forward(&ik.legs_mm);
        let _ = tricept_model::jacobian::error_jacobian(&machine, &ik.up);
    }
    let _ = machine.forward(&[700.0, 800.0, 900.0]);
}

/// `identify` end to end on arbitrary bytes: read the CSV, then identify
/// (robustly) on the paper's machine. Errors are fine; panics, hangs and
/// non-finite estimates reported as converged are not.
pub fn identify(bytes: &[u8]) {
    let Ok(data) = tricept_data::read_from(bytes, "fuzz.csv") else {
        return;
    };
    if data.poses.len() > 400 {
        return;
    }
    let machine = Machine::paper();
    let model = GeometricModel::new(machine.clone(), ParameterSet::paper15());
    if let Ok((identification, _)) =
        identify_robust(&model, &data, &IdentifyOptions::for_machine(&machine))
        && identification.converged
    {
        assert!(
            identification.estimate.iter().all(|v| v.is_finite()),
            "{:?}",
            identification.estimate
        );
    }
}
