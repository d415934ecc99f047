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

mod description_docs;

pub use self::description_docs::*;
pub use crate::commanding::{GeometricMachine, Machine};
pub use crate::linalg::Vector3;
/// Why a kinematics solve failed: a non-finite input, out of reach or
/// stroke, no assembly, not converged, singular.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{GeometricMachine, KinematicsError, Vector3};
/// let m = GeometricMachine::paper();
/// let e = m.inverse(&Vector3::new(f64::NAN, 0.0, 750.0)).unwrap_err();
/// assert!(matches!(e, KinematicsError::NotFinite { .. }), "{e}");
/// ```
#[doc(inline)]
pub use tricept_kinematics::KinematicsError;
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
/// The workspace cylinder of O' in solver form, mm.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{GeometricMachine, Vector3, Workspace};
/// let w: Workspace = GeometricMachine::paper().workspace;
/// assert_eq!((w.z_min_mm, w.z_max_mm, w.mid_plane_z_mm()), (650.0, 850.0, 750.0));
/// assert!(w.contains(&Vector3::new(400.0, 0.0, 700.0)));
/// assert!(!w.contains(&Vector3::new(0.0, 0.0, 900.0)));
/// ```
#[doc(inline)]
pub use tricept_kinematics::Workspace;
/// Rows [`run`] solves together (in parallel) before it writes them: the
/// memory a batch holds whatever its length.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{BLOCK_ROWS, GeometricMachine, Verb, run};
/// let csv = "x,y,z\n".to_string() + &"0,0,750\n".repeat(BLOCK_ROWS + 1);
/// let mut out = Vec::new();
/// let rows = run(Verb::Ik, &GeometricMachine::paper(), csv.as_bytes(), "p.csv", &mut out, || false)
///     .map_err(|e| e.to_string())?; // BatchError: Display, not std::error::Error
/// assert_eq!(rows, BLOCK_ROWS + 1); // two blocks, one output
/// assert_eq!(String::from_utf8(out)?.lines().count(), BLOCK_ROWS + 2);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::batch::BLOCK_ROWS;
/// Why [`run`] stopped: bad input, a point it cannot solve (with its line)
/// or a failed write.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{BatchError, GeometricMachine, Verb, run};
/// let csv = "x,y,z\n0,0,750\n0,0,5000\n";
/// let e = run(Verb::Ik, &GeometricMachine::paper(), csv.as_bytes(), "p.csv", Vec::new(), || false);
/// assert!(matches!(e, Err(BatchError::Point { line: 3, .. })));
/// let bad = run(Verb::Ik, &GeometricMachine::paper(), "x,y\n0,0\n".as_bytes(), "p.csv", Vec::new(), || false);
/// assert!(matches!(bad, Err(BatchError::Input(_))));
/// ```
#[doc(inline)]
pub use tricept_kinematics::batch::BatchError;
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
/// A machine [`run`] can solve points on: inverse and forward kinematics
/// of the platform point.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{ExtendedMachine, GeometricMachine, PointKinematics, Vector3};
/// fn first_leg_mm(m: &dyn PointKinematics) -> f64 {
///     m.inverse(&Vector3::new(0.0, 0.0, 750.0)).map_or(f64::NAN, |ik| ik.legs_mm[0])
/// }
/// let nominal = ExtendedMachine::new(GeometricMachine::paper());
/// assert!((first_leg_mm(&GeometricMachine::paper()) - 773.3).abs() < 0.1);
/// assert_eq!(first_leg_mm(&GeometricMachine::paper()), first_leg_mm(&nominal));
/// ```
#[doc(inline)]
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
/// Solves the rows of a CSV of `verb`'s inputs on `machine` and writes its
/// keys' CSV to `out`, in blocks of [`BLOCK_ROWS`]; returns the rows written
/// (the door's errors: [`solve_batch`]).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{GeometricMachine, Verb, run};
/// let mut out = Vec::new();
/// let csv = "x,y,z\n0,0,750\n10,0,750\n";
/// let rows = run(Verb::Ik, &GeometricMachine::paper(), csv.as_bytes(), "p.csv", &mut out, || false)
///     .map_err(|e| e.to_string())?; // BatchError: Display, not std::error::Error
/// assert_eq!(rows, 2);
/// assert!(String::from_utf8(out)?.starts_with("x,y,z,q1,q2,q3"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::batch::run;
/// Why a machine description was refused: bad JSON, an unreadable file, a
/// newer format, or a value out of range.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{DescriptionError, MachineDescription};
/// let e = MachineDescription::from_json("{ not json").unwrap_err();
/// assert!(matches!(e, DescriptionError::Json { .. }), "{e}");
/// let newer = MachineDescription::paper().to_json().replace("\"format_version\": 1", "\"format_version\": 99");
/// assert!(matches!(MachineDescription::from_json(&newer), Err(DescriptionError::NewerFormat(_))));
/// ```
#[doc(inline)]
pub use tricept_kinematics::error::DescriptionError;
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
/// The 2-axis head in solver form (unit axes, points on them, tool tip),
/// in the platform frame.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{GeometricMachine, Head, HeadDescription};
/// let head: Head = GeometricMachine::paper().head;
/// assert_eq!(head.to_description(), HeadDescription::default());
/// assert_eq!(Head::from_description(&HeadDescription::default()), head);
/// ```
#[doc(inline)]
pub use tricept_kinematics::head::Head;
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
/// A tool pose: tip (mm) and unit tool axis.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{GeometricMachine, ToolPose, Vector3};
/// let pose: ToolPose = GeometricMachine::paper().head.tool_in_platform([0.0, 0.0]);
/// assert!((pose.tip_mm - Vector3::new(0.0, 0.0, 350.0)).norm() < 1e-12);
/// assert!((pose.axis.norm() - 1.0).abs() < 1e-12);
/// ```
#[doc(inline)]
pub use tricept_kinematics::head::ToolPose;
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
/// The three legs at one configuration: platform joints, geometric lengths
/// (mm) and unit directions.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{GeometricMachine, LegGeometry, Vector3};
/// let m = GeometricMachine::paper();
/// let ik = m.inverse(&Vector3::new(20.0, 10.0, 770.0))?;
/// let legs: LegGeometry = m.legs_at(&ik.up);
/// for i in 0..3 { // nominal: length = command
///     assert!((legs.lengths_mm[i] - ik.legs_mm[i]).abs() < 1e-9);
///     assert!((legs.directions[i].norm() - 1.0).abs() < 1e-12);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::machine::LegGeometry;
/// Joint limits in solver form: strokes (mm) and the UP limb's largest tilt (rad).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{GeometricMachine, Limits};
/// let l: Limits = GeometricMachine::paper().limits;
/// assert!((l.max_tilt_rad() - 40f64.to_radians()).abs() < 1e-15);
/// assert_eq!(Limits::new([450.0, 1250.0], l.up_stroke_mm, l.max_tilt_rad()), l);
/// ```
#[doc(inline)]
pub use tricept_kinematics::machine::Limits;
/// A machine's sensor noise in solver form: one reading's encoder (rad) and
/// scale (mm) noise, and the readings averaged per logged value.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{LoggedSensorNoise, SensorDescription};
/// let n = LoggedSensorNoise::from_description(&SensorDescription::default());
/// assert!((n.length_mm - 0.0005).abs() < 1e-15); // 0.5 um
/// let [_, _, s_mm] = n.logged_sigma(); // the mean of 3 readings
/// assert!((s_mm - 0.0005 / 3f64.sqrt()).abs() < 1e-15);
/// ```
#[doc(inline)]
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
/// The UP limb's chain: axis order and class-2 errors (skew, offset, twist).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{AxisOrder, GeometricMachine, UpLimb};
/// let limb: UpLimb = GeometricMachine::paper().up_limb;
/// assert!(limb.is_ideal());
/// assert_eq!(limb, UpLimb::ideal(AxisOrder::XFirst));
/// ```
#[doc(inline)]
pub use tricept_kinematics::up_limb::UpLimb;
/// The UP limb at one joint configuration: platform orientation and point
/// (mm), limb axis and the angle axes.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{GeometricMachine, UpLimbPose, Vector3};
/// let m = GeometricMachine::paper();
/// let target = Vector3::new(-40.0, 25.0, 780.0);
/// let pose: UpLimbPose = m.up_limb.pose(&m.inverse(&target)?.up);
/// assert!((pose.position_mm - target).norm() < 1e-9);
/// assert!((pose.limb_axis.norm() - 1.0).abs() < 1e-12);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::up_limb::UpLimbPose;

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
