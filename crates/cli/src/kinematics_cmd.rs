//! The kinematics verbs: `ik`, `fk`, `tool-ik`, `machine`.

use clap::Args;
use nalgebra::Vector3;
use serde_json::Value;
use tricept_kinematics::{HeadBranch, MachineDescription, UpJoints};

use crate::args::{MachineArgs, load_machine};
use crate::cli_error::CliError;
use crate::output::print_record;

/// `tricept ik X Y Z`.
#[derive(Debug, Args)]
pub struct IkArgs {
    /// x of O' in the base frame, mm.
    pub x: f64,
    /// y of O' in the base frame, mm.
    pub y: f64,
    /// z of O' in the base frame, mm.
    pub z: f64,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept fk Q1 Q2 Q3`.
#[derive(Debug, Args)]
pub struct FkArgs {
    /// Command of leg 1, mm.
    pub q1: f64,
    /// Command of leg 2, mm.
    pub q2: f64,
    /// Command of leg 3, mm.
    pub q3: f64,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept tool-ik X Y Z AX AY AZ`.
#[derive(Debug, Args)]
pub struct ToolIkArgs {
    /// Tool tip x, mm.
    pub x: f64,
    /// Tool tip y, mm.
    pub y: f64,
    /// Tool tip z, mm.
    pub z: f64,
    /// Tool axis x component (any length).
    pub ax: f64,
    /// Tool axis y component.
    pub ay: f64,
    /// Tool axis z component.
    pub az: f64,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept machine`.
#[derive(Debug, Args)]
pub struct MachineVerbArgs {
    #[command(flatten)]
    pub machine: MachineArgs,
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
pub fn ik(a: &IkArgs) -> Result<(), CliError> {
    let m = load_machine(&a.machine)?;
    let sol = m
        .inverse(&Vector3::new(a.x, a.y, a.z))
        .map_err(|e| CliError::kinematics("ik", &e))?;
    print_record(a.machine.json, &legs_and_up(&sol.legs_mm, &sol.up));
    Ok(())
}

/// `tricept fk Q1 Q2 Q3`.
pub fn fk(a: &FkArgs) -> Result<(), CliError> {
    let m = load_machine(&a.machine)?;
    let sol = m
        .forward(&[a.q1, a.q2, a.q3])
        .map_err(|e| CliError::kinematics("fk", &e))?;
    print_record(
        a.machine.json,
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
pub fn tool_ik(a: &ToolIkArgs) -> Result<(), CliError> {
    let m = load_machine(&a.machine)?;
    let sol = m
        .tool_inverse(
            &Vector3::new(a.x, a.y, a.z),
            &Vector3::new(a.ax, a.ay, a.az),
            HeadBranch::default(),
        )
        .map_err(|e| CliError::kinematics("tool-ik", &e))?;
    let mut record = legs_and_up(&sol.legs_mm, &sol.up);
    record.extend([
        ("h1", sol.head_rad[0].into()),
        ("h2", sol.head_rad[1].into()),
        ("head_singular", Value::Bool(sol.head_singular)),
    ]);
    print_record(a.machine.json, &record);
    Ok(())
}

/// `tricept machine`: prints the description in use.
pub fn print_machine(a: &MachineVerbArgs) -> Result<(), CliError> {
    let description = match &a.machine.machine {
        None => MachineDescription::paper(),
        Some(path) => MachineDescription::from_file(path)
            .map_err(|e| CliError::description(&path.display().to_string(), &e))?,
    };
    outln!("{}", description.to_json());
    Ok(())
}
