//! The kinematics verbs: `ik`, `fk`, `tool-ik`, `machine`.

use nalgebra::Vector3;
use serde_json::Value;
use tricept_kinematics::{HeadBranch, Machine, MachineDescription, UpJoints};

use crate::MachineArgs;
use crate::cli_error::CliError;
use crate::output::print_record;

/// Loads the machine named by `--machine`, or the embedded default.
pub fn load_machine(args: &MachineArgs) -> Result<Machine, CliError> {
    let description = match &args.machine {
        None => MachineDescription::paper(),
        Some(path) => MachineDescription::from_file(path)
            .map_err(|e| CliError::description(&path.display().to_string(), &e))?,
    };
    description
        .build()
        .map_err(|e| CliError::description("machine", &e))
}

/// The record keys shared by `ik` and `tool-ik`: `q1 q2 q3` (mm),
/// `phi theta` (rad), `q4` (mm).
fn legs_and_up(legs_mm: &[f64; 3], up: &UpJoints) -> Vec<(&'static str, Value)> {
    vec![
        ("q1", legs_mm[0].into()),
        ("q2", legs_mm[1].into()),
        ("q3", legs_mm[2].into()),
        ("phi", up.phi_rad.into()),
        ("theta", up.theta_rad.into()),
        ("q4", up.q4_mm.into()),
    ]
}

/// `tricept ik X Y Z`.
pub fn ik(args: &MachineArgs, r: [f64; 3]) -> Result<(), CliError> {
    let m = load_machine(args)?;
    let sol = m
        .inverse(&Vector3::from(r))
        .map_err(|e| CliError::kinematics("ik", &e))?;
    print_record(args.json, &legs_and_up(&sol.legs_mm, &sol.up));
    Ok(())
}

/// `tricept fk Q1 Q2 Q3`.
pub fn fk(args: &MachineArgs, q: [f64; 3]) -> Result<(), CliError> {
    let m = load_machine(args)?;
    let sol = m.forward(&q).map_err(|e| CliError::kinematics("fk", &e))?;
    print_record(
        args.json,
        &[
            ("x", sol.position_mm.x.into()),
            ("y", sol.position_mm.y.into()),
            ("z", sol.position_mm.z.into()),
            ("phi", sol.up.phi_rad.into()),
            ("theta", sol.up.theta_rad.into()),
            ("q4", sol.up.q4_mm.into()),
            ("condition", sol.condition.into()),
            ("iterations", sol.iterations.into()),
        ],
    );
    Ok(())
}

/// `tricept tool-ik X Y Z AX AY AZ`.
pub fn tool_ik(args: &MachineArgs, tip: [f64; 3], axis: [f64; 3]) -> Result<(), CliError> {
    let m = load_machine(args)?;
    let sol = m
        .tool_inverse(
            &Vector3::from(tip),
            &Vector3::from(axis),
            HeadBranch::default(),
        )
        .map_err(|e| CliError::kinematics("tool-ik", &e))?;
    let mut record = legs_and_up(&sol.legs_mm, &sol.up);
    record.extend([
        ("h1", sol.head_rad[0].into()),
        ("h2", sol.head_rad[1].into()),
        ("head_singular", Value::Bool(sol.head_singular)),
    ]);
    print_record(args.json, &record);
    Ok(())
}

/// `tricept machine`: prints the description in use.
pub fn print_machine(args: &MachineArgs) -> Result<(), CliError> {
    let description = match &args.machine {
        None => MachineDescription::paper(),
        Some(path) => MachineDescription::from_file(path)
            .map_err(|e| CliError::description(&path.display().to_string(), &e))?,
    };
    outln!("{}", description.to_json());
    Ok(())
}
