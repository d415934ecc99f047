//! The kinematics verbs: `ik`, `fk`, `tool-ik` (one point from the command
//! line, or many from `--input FILE.csv|-`), and `machine`.
//!
//! A calibrated machine file's static leg effects (lead, compliance) are
//! applied ([`tricept_model::ExtendedMachine`]).

use std::path::PathBuf;

use clap::Args;
use tricept_cli::batch::{self, BatchError, Verb};
use tricept_kinematics::{Machine, MachineDescription};
use tricept_model::ExtendedMachine;

use crate::args::{MachineArgs, load};
use crate::cli_error::CliError;
use crate::output::{Field, print_record, stdout_closed};

/// Where the points of a batch come from.
#[derive(Debug, Args, Clone)]
pub struct InputArgs {
    /// Read many points from a CSV file (`-`: stdin) with the verb's input
    /// columns (ik: x,y,z in mm; fk: q1,q2,q3 in mm; tool-ik: x,y,z in mm
    /// and ax,ay,az) and write CSV to stdout, the keys of --json as columns.
    #[arg(long, value_name = "FILE.csv")]
    pub input: Option<PathBuf>,
}

/// `tricept ik X Y Z`.
#[derive(Debug, Args)]
pub struct IkArgs {
    /// x of O' in the base frame, mm.
    #[arg(required_unless_present = "input")]
    pub x: Option<f64>,
    /// y of O' in the base frame, mm.
    #[arg(required_unless_present = "input")]
    pub y: Option<f64>,
    /// z of O' in the base frame, mm.
    #[arg(required_unless_present = "input")]
    pub z: Option<f64>,
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept fk Q1 Q2 Q3`.
#[derive(Debug, Args)]
pub struct FkArgs {
    /// Command of leg 1, mm.
    #[arg(required_unless_present = "input")]
    pub q1: Option<f64>,
    /// Command of leg 2, mm.
    #[arg(required_unless_present = "input")]
    pub q2: Option<f64>,
    /// Command of leg 3, mm.
    #[arg(required_unless_present = "input")]
    pub q3: Option<f64>,
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept tool-ik X Y Z AX AY AZ`.
#[derive(Debug, Args)]
pub struct ToolIkArgs {
    /// Tool tip x, mm.
    #[arg(required_unless_present = "input")]
    pub x: Option<f64>,
    /// Tool tip y, mm.
    #[arg(required_unless_present = "input")]
    pub y: Option<f64>,
    /// Tool tip z, mm.
    #[arg(required_unless_present = "input")]
    pub z: Option<f64>,
    /// Tool axis x component (unitless, any length).
    #[arg(required_unless_present = "input")]
    pub ax: Option<f64>,
    /// Tool axis y component (unitless).
    #[arg(required_unless_present = "input")]
    pub ay: Option<f64>,
    /// Tool axis z component (unitless).
    #[arg(required_unless_present = "input")]
    pub az: Option<f64>,
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept machine`.
#[derive(Debug, Args)]
pub struct MachineVerbArgs {
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// One point or a batch, for any of the three verbs.
fn kinematics(
    verb: Verb,
    point: &[Option<f64>],
    input: &InputArgs,
    machine: &MachineArgs,
) -> Result<u8, CliError> {
    let m = ExtendedMachine::new(load(machine)?.machine().clone());
    if let Some(path) = &input.input {
        if point.iter().any(Option::is_some) {
            return Err(CliError::input(format!(
                "{}: give either a point on the command line or --input, not both",
                verb.name()
            )));
        }
        if machine.json {
            return Err(CliError::input(format!(
                "{} --input: the output is CSV (the --json keys as columns); leave out --json",
                verb.name()
            )));
        }
        return run_batch(verb, &m, path);
    }
    let values: Vec<f64> = point.iter().map(|v| v.unwrap_or(f64::NAN)).collect();
    let cells = verb
        .solve(&m, &values)
        .map_err(|e| CliError::with_context(verb.name(), &e))?;
    let fields: Vec<Field> = verb
        .keys()
        .iter()
        .zip(verb.units())
        .zip(cells)
        .map(|((k, u), c)| (*k, c.to_json(), *u))
        .collect();
    print_record(machine.json, &fields);
    Ok(0)
}

fn run_batch(verb: Verb, m: &ExtendedMachine, path: &std::path::Path) -> Result<u8, CliError> {
    let out = std::io::BufWriter::with_capacity(1 << 16, crate::output::Stdout);
    let result = if path.as_os_str() == "-" {
        batch::run(
            verb,
            m,
            std::io::stdin().lock(),
            "stdin",
            out,
            stdout_closed,
        )
    } else {
        let name = path.display().to_string();
        let f = std::fs::File::open(path).map_err(|e| CliError::input(format!("{name}: {e}")))?;
        batch::run(verb, m, f, &name, out, stdout_closed)
    };
    let file = path.display().to_string();
    match result {
        Ok(_) => Ok(0),
        Err(BatchError::Input(message)) => Err(CliError::input(message)),
        Err(BatchError::Point { line, source }) => Err(CliError::with_context(
            format!("{} --input {file}: line {line}", verb.name()),
            &source,
        )),
        Err(BatchError::Output(message)) => Err(CliError::other(format!("stdout: {message}"))),
    }
}

/// `tricept ik X Y Z`.
pub fn ik(a: &IkArgs) -> Result<u8, CliError> {
    kinematics(Verb::Ik, &[a.x, a.y, a.z], &a.input, &a.machine)
}

/// `tricept fk Q1 Q2 Q3`.
pub fn fk(a: &FkArgs) -> Result<u8, CliError> {
    kinematics(Verb::Fk, &[a.q1, a.q2, a.q3], &a.input, &a.machine)
}

/// `tricept tool-ik X Y Z AX AY AZ`.
pub fn tool_ik(a: &ToolIkArgs) -> Result<u8, CliError> {
    kinematics(
        Verb::ToolIk,
        &[a.x, a.y, a.z, a.ax, a.ay, a.az],
        &a.input,
        &a.machine,
    )
}

/// `tricept machine`: the description in use, as JSON (`--json`, the file
/// format) or as a summary with units.
pub fn print_machine(a: &MachineVerbArgs) -> Result<u8, CliError> {
    let loaded = load(&a.machine)?;
    if a.machine.json {
        outln!("{}", loaded.description().to_json());
        return Ok(0);
    }
    summary(loaded.description(), loaded.machine(), loaded.source());
    Ok(0)
}

fn summary(d: &MachineDescription, m: &Machine, source: &str) {
    let v = |p: &nalgebra::Vector3<f64>| format!("({:.3}, {:.3}, {:.3})", p.x, p.y, p.z);
    outln!("{} (from {source})", d.name);
    if let Some(n) = &d.notes {
        outln!("  notes: {n}");
    }
    for i in 0..3 {
        outln!(
            "  leg {}: base joint B{} {} mm, platform joint A{} {} mm, length offset {:.4} mm",
            i + 1,
            i + 1,
            v(&m.base_joints_mm[i]),
            i + 1,
            v(&m.platform_joints_mm[i]),
            m.leg_offsets_mm[i]
        );
    }
    let u = &m.up_limb;
    outln!(
        "  UP limb: {} U joint; axis skew {:.3e} rad, axis offset {:.4} mm, twist {:.3e} rad/mm about {:.1} mm",
        u.axis_order,
        u.axis_skew_rad,
        u.axis_offset_mm,
        u.twist_rad_per_mm,
        u.twist_reference_mm
    );
    let w = &m.workspace;
    outln!(
        "  workspace: cylinder of radius {} mm, z from {} to {} mm",
        w.radius_mm,
        w.z_min_mm,
        w.z_max_mm
    );
    let l = &d.limits;
    outln!(
        "  limits: leg stroke {:?} mm, UP stroke {:?} mm, tilt {} deg",
        l.leg_stroke_mm,
        l.up_stroke_mm,
        l.max_tilt_deg
    );
    let s = &d.sensors;
    outln!(
        "  sensors: encoder noise {} arcsec, scale noise {} um per reading, mean of {}",
        s.angle_noise_arcsec,
        s.length_noise_um,
        s.readings_per_pose
    );
    let e = &d.leg_effects;
    if !e.is_zero() {
        outln!(
            "  leg effects (applied by ik, fk, tool-ik, compensate): lead {:?} ppm, compliance {} um/kN at 1 m",
            e.lead_ppm,
            e.compliance_um_per_kn_at_1m
        );
    }
    if let Some(c) = &d.controller {
        outln!(
            "  controller parameters: backlash {:?} um per leg axis, thermal expansion {} ppm/K from {} °C",
            c.backlash_um,
            c.thermal_expansion_ppm_per_k,
            c.reference_temperature_c
        );
    }
    if let Some(c) = &d.calibration {
        outln!(
            "  calibration: {} from {} ({}, sha256 {}), {}: {} parameters, {} held, chi2/dof {:.3}, converged {}, adequate {}{}",
            c.method,
            c.data_file,
            c.date,
            &c.data_sha256[..c.data_sha256.len().min(12)],
            c.parameter_set,
            c.estimates_mm.len(),
            c.held.len(),
            c.chi2_per_dof,
            c.converged,
            c.adequate,
            if c.forced { ", FORCED" } else { "" }
        );
    }
    outln!("  (tricept machine --json prints the description file)");
}
