//! The kinematics workflows (`tricept ik`, `fk`, `tool-ik` and `machine`):
//! one point solved on a machine with its static leg effects applied
//! ([`solve_point`]), many points streamed from CSV in blocks of
//! [`BLOCK_ROWS`] rows ([`run`], and [`solve_batch`] with the door's
//! errors), and the summary of a machine description
//! ([`machine_summary`]); the machine a program commands ([`Machine`])
//! and the solutions it returns ([`IkSolution`], [`FkSolution`],
//! [`ToolIkSolution`]).
//!
//! # Example
//! ```
//! use tricept_ident::kinematics::{Machine, Vector3};
//! let ik = Machine::paper().inverse(&Vector3::new(0.0, 0.0, 750.0))?;
//! assert!((ik.legs_mm[0] - 773.3).abs() < 0.1);
//! # Ok::<(), tricept_ident::Error>(())
//! ```

use std::io::{Read, Write};

use serde_json::{Map, Value};

use crate::error::{EXIT_OK, Error};
use crate::inputs::LoadedMachine;

pub use crate::commanding::{GeometricMachine, Machine};
pub use crate::linalg::Vector3;
/// A machine file's contents: the description every `--machine` loads.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{Machine, MachineDescription};
/// let description: MachineDescription = Machine::paper().to_description();
/// assert_eq!(Machine::from_description(&description, "paper")?, Machine::paper());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::MachineDescription;
/// One value of a solved point ([`PointSolution::cells`]).
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::kinematics::{Cell, Verb, solve_point};
/// let solved = solve_point(Verb::Ik, &MachineInput::default().load()?, &[0.0, 0.0, 750.0])?;
/// let numbers = solved.cells().iter().filter(|c| matches!(c, Cell::Num(_))).count();
/// assert!(numbers >= 6);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::batch::Cell;
pub use tricept_kinematics::batch::PointKinematics;
/// The kinematics verbs [`solve_point`] and [`run`] solve.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::Verb;
/// assert_eq!(Verb::Ik.inputs(), ["x", "y", "z"]);
/// assert_eq!(Verb::Ik.keys()[3], "q1");
/// ```
#[doc(inline)]
pub use tricept_kinematics::batch::Verb;
pub use tricept_kinematics::batch::{BLOCK_ROWS, BatchError, run};
pub use tricept_kinematics::description::{
    AccuracyRecord, AxisOrder, CalibrationRecord, CircularPlacement, ControllerDescription,
    CorrelationsDescription, ExplicitPlacement, ExternalSourceRecord, HeadDescription,
    HeldParameter, Interpolation, LegEffectsDescription, LegTableDescription, LimitsDescription,
    LoadsDescription, Placement, SealCheck, SensorDescription, SensorOffsetsDescription,
    UpLimbDescription, WorkspaceDescription,
};
/// A solution of [`Machine::forward`].
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{FkSolution, Machine, Vector3};
/// let m = Machine::paper();
/// let target = Vector3::new(50.0, -20.0, 760.0);
/// let fk: FkSolution = m.forward(&m.inverse(&target)?.legs_mm)?;
/// assert!((fk.position_mm - target).norm() < 1e-8);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::fk::FkSolution;
/// Which head solution a tool pose's inverse kinematics returns.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::HeadBranch;
/// assert_eq!(HeadBranch::default(), HeadBranch::PositiveSecondAxis);
/// let near = HeadBranch::Nearest([0.1, -0.2]);
/// assert_ne!(near, HeadBranch::default());
/// ```
#[doc(inline)]
pub use tricept_kinematics::head::HeadBranch;
/// A solution of [`Machine::tool_inverse`].
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{Machine, ToolIkSolution, Vector3};
/// let m = Machine::paper();
/// let tip = Vector3::new(0.0, 0.0, 900.0);
/// let s: ToolIkSolution = m.tool_inverse(&tip, &Vector3::new(0.0, 0.0, 1.0))?;
/// assert!(s.legs_mm.iter().all(|q| q.is_finite()));
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::head::ToolIkSolution;
/// A solution of [`Machine::inverse`].
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{IkSolution, Machine, Vector3};
/// let ik: IkSolution = Machine::paper().inverse(&Vector3::new(0.0, 0.0, 750.0))?;
/// assert!((ik.legs_mm[0] - 773.3).abs() < 0.1);
/// assert!(ik.up.q4_mm > 0.0);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::machine::IkSolution;
pub use tricept_kinematics::machine::SensorNoise as LoggedSensorNoise;
/// The UP limb's joints of a pose (an [`IkSolution`]'s `up`).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{Machine, UpJoints, Vector3};
/// let up: UpJoints = Machine::paper().inverse(&Vector3::new(0.0, 0.0, 750.0))?.up;
/// assert!(up.phi_rad.abs() < 1e-9 && up.theta_rad.abs() < 1e-9);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::up_limb::UpJoints;
pub use tricept_kinematics::{
    KinematicsError, Workspace, error::DescriptionError, head::Head, head::ToolPose,
    machine::LegGeometry, machine::Limits, up_limb::UpLimb, up_limb::UpLimbPose,
};

/// The geometric machine with its static leg effects, as [`Machine::extended`] holds it.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{ExtendedMachine, GeometricMachine, Machine};
/// let extended = ExtendedMachine::new(GeometricMachine::paper());
/// assert_eq!(&extended, Machine::paper().extended());
/// ```
#[doc(inline)]
pub use tricept_model::ExtendedMachine;

/// Runs `verb` on every row of `input` ([`run`]) as the CLI does:
/// `file` names the input in its messages, `label` in the message of a
/// point that cannot be solved (`VERB --input LABEL: line N: ...`, of that
/// error's kind); a failed write is an error of kind other naming stdout.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{ExtendedMachine, GeometricMachine, Verb, solve_batch};
/// let machine = ExtendedMachine::new(GeometricMachine::paper());
/// let mut out = Vec::new();
/// let rows = solve_batch(Verb::Ik, &machine, "x,y,z\n0,0,750\n".as_bytes(), "points.csv", "points.csv", &mut out, || false)?;
/// assert_eq!(rows, 1);
/// assert!(String::from_utf8_lossy(&out).contains("773.3"));
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn solve_batch<R: Read, W: Write>(
    verb: Verb,
    machine: &ExtendedMachine,
    input: R,
    file: &str,
    label: &str,
    out: W,
    stop: impl Fn() -> bool,
) -> Result<usize, Error> {
    run(verb, machine, input, file, out, stop).map_err(|e| match e {
        BatchError::Input(message) => Error::input(message),
        BatchError::Point { line, source } => Error::from_library(source)
            .in_file(format!("line {line}"))
            .in_setting_value(crate::Setting::Input, label)
            .in_file(verb.name()),
        BatchError::Output(message) => Error::other(format!("stdout: {message}")),
    })
}

/// One point solved by a kinematics verb.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::kinematics::{Cell, Verb, solve_point};
/// let s = solve_point(Verb::Ik, &MachineInput::default().load()?, &[0.0, 0.0, 750.0])?;
/// assert!(matches!(s.cells()[3], Cell::Num(q1) if (q1 - 773.3).abs() < 0.1));
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct PointSolution {
    verb: Verb,
    cells: Vec<Cell>,
}

crate::outcome::outcome!(PointSolution);

/// Solves one point (`point` in the order of [`Verb::inputs`]) on
/// `machine` with its static leg effects applied; an unreachable point is
/// an input error naming the verb.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::kinematics::{Verb, solve_point};
/// let m = MachineInput::default().load().unwrap();
/// let s = solve_point(Verb::Ik, &m, &[0.0, 0.0, 750.0]).unwrap();
/// assert!(s.to_json().to_string().starts_with(r#"{"format_version":1,"x":0.0,"y":0.0,"z":750.0,"q1":773.3"#));
/// assert!(solve_point(Verb::Ik, &m, &[0.0, 0.0, 5000.0]).is_err());
/// ```
pub fn solve_point(
    verb: Verb,
    machine: &LoadedMachine,
    point: &[f64],
) -> Result<PointSolution, Error> {
    if point.len() != verb.inputs().len() {
        return Err(Error::input(format!(
            "{}: expected {} values ({}), got {}",
            verb.name(),
            verb.inputs().len(),
            verb.inputs().join(", "),
            point.len()
        )));
    }
    let m = ExtendedMachine::new(machine.machine().clone());
    let cells = verb
        .solve(&m, point)
        .map_err(|e| Error::with_context(verb.name(), e))?;
    Ok(PointSolution { verb, cells })
}

impl PointSolution {
    /// The values in the order of [`Verb::keys`].
    pub fn cells(&self) -> &[Cell] {
        &self.cells
    }

    /// Always 0: a solved point has no verdict.
    pub fn exit_code(&self) -> u8 {
        EXIT_OK
    }

    /// Always `None`: a solved point has no verdict.
    pub fn reason(&self) -> Option<&str> {
        None
    }

    /// The solution as one JSON object (what the verb's `--json` prints),
    /// `format_version` first, then the verb's keys in order.
    pub fn to_json(&self) -> Value {
        let map: Map<String, Value> = self
            .verb
            .keys()
            .iter()
            .zip(&self.cells)
            .map(|(k, c)| (k.to_string(), c.to_json()))
            .collect();
        crate::outcome::versioned(Value::Object(map))
    }

    /// The solution as aligned `key = value unit` lines (what the verb
    /// prints).
    pub fn report(&self) -> String {
        let keys = self.verb.keys();
        let width = keys.iter().map(|k| k.len()).max().unwrap_or(0);
        let mut out = String::new();
        for ((k, unit), c) in keys.iter().zip(self.verb.units()).zip(&self.cells) {
            let text = match c {
                Cell::Num(x) => format!("{x:.9}"),
                Cell::Int(i) => i.to_string(),
                Cell::Bool(b) => b.to_string(),
            };
            if unit.is_empty() {
                out.push_str(&format!("{k:>width$} = {text}\n"));
            } else {
                out.push_str(&format!("{k:>width$} = {text} {unit}\n"));
            }
        }
        out
    }
}

/// A summary of the machine in use with units (`tricept machine`): the
/// joints, the UP limb, the workspace, the limits, the sensors, the leg
/// effects, the controller parameters and the calibration record.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::kinematics::machine_summary;
/// let summary = machine_summary(&MachineInput::default().load()?);
/// assert!(!summary.is_empty());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn machine_summary(loaded: &LoadedMachine) -> String {
    let (d, m, source) = (loaded.description(), loaded.machine(), loaded.source());
    let v = |p: &Vector3| format!("({:.3}, {:.3}, {:.3})", p.x, p.y, p.z);
    let mut lines = vec![format!("{} (from {source})", d.name)];
    if let Some(n) = &d.notes {
        lines.push(format!("  notes: {n}"));
    }
    for i in 0..3 {
        lines.push(format!(
            "  leg {}: base joint B{} {} mm, platform joint A{} {} mm, length offset {:.4} mm",
            i + 1,
            i + 1,
            v(&m.base_joints_mm[i]),
            i + 1,
            v(&m.platform_joints_mm[i]),
            m.leg_offsets_mm[i]
        ));
    }
    let u = &m.up_limb;
    lines.push(format!(
        "  UP limb: {} U joint; axis skew {:.3e} rad, axis offset {:.4} mm, twist {:.3e} rad/mm about {:.1} mm",
        u.axis_order,
        u.axis_skew_rad,
        u.axis_offset_mm,
        u.twist_rad_per_mm,
        u.twist_reference_mm
    ));
    let w = &m.workspace;
    lines.push(format!(
        "  workspace: cylinder of radius {} mm, z from {} to {} mm",
        w.radius_mm, w.z_min_mm, w.z_max_mm
    ));
    let l = &d.limits;
    lines.push(format!(
        "  limits: leg stroke {:?} mm, UP stroke {:?} mm, tilt {} deg",
        l.leg_stroke_mm, l.up_stroke_mm, l.max_tilt_deg
    ));
    let s = &d.sensors;
    lines.push(format!(
        "  sensors: encoder noise {} arcsec, scale noise {} um per reading, mean of {}",
        s.angle_noise_arcsec, s.length_noise_um, s.readings_per_pose
    ));
    let e = &d.leg_effects;
    if !e.is_zero() {
        lines.push(format!(
            "  leg effects (applied by ik, fk, tool-ik, compensate): lead {:?} ppm, compliance {} um/kN at 1 m",
            e.lead_ppm, e.compliance_um_per_kn_at_1m
        ));
    }
    if let Some(c) = &d.controller {
        lines.push(format!(
            "  controller parameters: backlash {:?} um per leg axis, thermal expansion {} ppm/K from {} °C",
            c.backlash_um, c.thermal_expansion_ppm_per_k, c.reference_temperature_c
        ));
    }
    if let Some(c) = &d.calibration {
        lines.push(format!(
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
        ));
    }
    lines.join("\n") + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::{SensorNoise, load_machine};

    #[test]
    fn ik_then_fk_returns_the_point_and_text_aligns_keys_with_units() {
        let m = load_machine(None, &SensorNoise::default()).unwrap();
        let ik = solve_point(Verb::Ik, &m, &[100.0, -50.0, 760.0]).unwrap();
        let q: Vec<f64> = ik.cells()[3..6]
            .iter()
            .map(|c| match c {
                Cell::Num(x) => *x,
                _ => f64::NAN,
            })
            .collect();
        let fk = solve_point(Verb::Fk, &m, &q).unwrap();
        let v = fk.to_json();
        for (k, want) in [("x", 100.0), ("y", -50.0), ("z", 760.0)] {
            assert!((v[k].as_f64().unwrap() - want).abs() < 1e-6, "{k}");
        }
        let text = ik.report();
        assert!(
            text.lines().nth(3).unwrap().starts_with("   q1 = "),
            "{text}"
        );
        assert!(text.lines().nth(3).unwrap().ends_with(" mm"), "{text}");
        assert!(text.lines().all(|l| l.contains(" = ")));
        assert!(solve_point(Verb::Ik, &m, &[0.0, 0.0]).is_err());
    }

    #[test]
    fn a_batch_point_out_of_reach_names_the_verb_input_and_line() {
        let m = ExtendedMachine::new(tricept_kinematics::Machine::paper());
        let csv = "x,y,z\n0,0,750\n0,0,5000\n";
        let mut out = Vec::new();
        let e = solve_batch(Verb::Ik, &m, csv.as_bytes(), "stdin", "-", &mut out, || {
            false
        })
        .unwrap_err();
        assert_eq!(e.exit_code(), crate::EXIT_INPUT);
        assert!(
            e.message().starts_with("ik: input -: line 3: ")
                && e.message_naming(|_| "--input")
                    .starts_with("ik: --input -: line 3: "),
            "{}",
            e.message()
        );
        assert_eq!(String::from_utf8(out).unwrap().lines().count(), 2);
    }
}
