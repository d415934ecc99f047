//! The kinematics workflows (`tricept ik`, `fk`, `tool-ik` and `machine`):
//! one point solved on a machine with its static leg effects applied
//! ([`solve_point`]), many points streamed from CSV ([`run`],
//! [`solve_batch`]), and the summary of a machine description
//! ([`machine_summary`]).
//!
//! Batch kinematics: many points from a CSV stream through `ik`, `fk` or
//! `tool-ik`, written as CSV with the keys of the verbs' `--json` output as
//! columns (inputs first), in input order.
//!
//! Input is read with the measured-data rules of `tricept-data` (header,
//! any column order, `#` comments, byte-order mark, the same messages) and
//! streamed: rows are solved in blocks of [`BLOCK_ROWS`], the blocks' rows
//! in parallel (each point is independent, so the output is the same at any
//! thread count), and written as they are done; memory does not grow with
//! the input. The first row that cannot be solved stops the batch with an
//! error naming its line (the rows before it have been written).

use std::io::{Read, Write};

use rayon::prelude::*;
use serde_json::{Map, Value};
use tricept_data::NumericRows;

use crate::error::{EXIT_OK, Error};
use crate::inputs::LoadedMachine;

pub use crate::commanding::{GeometricMachine, Machine, Vector3};
pub use tricept_kinematics::{
    FkSolution, HeadBranch, IkSolution, KinematicsError, MachineDescription, ToolIkSolution,
    UpJoints,
};
pub use tricept_model::ExtendedMachine;

/// Rows solved per block.
pub const BLOCK_ROWS: usize = 8192;

/// The verb of a batch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verb {
    /// Platform point `x,y,z` to leg commands and UP joints.
    Ik,
    /// Leg commands `q1,q2,q3` to the UP joints and the platform point.
    Fk,
    /// Tool tip `x,y,z` and axis `ax,ay,az` to commands and head angles.
    ToolIk,
}

/// One output value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cell {
    /// A real number.
    Num(f64),
    /// A count.
    Int(u32),
    /// A flag.
    Bool(bool),
}

impl Cell {
    /// As JSON.
    pub fn to_json(self) -> serde_json::Value {
        match self {
            Cell::Num(x) => x.into(),
            Cell::Int(i) => i.into(),
            Cell::Bool(b) => b.into(),
        }
    }
}

impl Verb {
    /// The input columns.
    pub fn inputs(self) -> &'static [&'static str] {
        match self {
            Verb::Ik => &["x", "y", "z"],
            Verb::Fk => &["q1", "q2", "q3"],
            Verb::ToolIk => &["x", "y", "z", "ax", "ay", "az"],
        }
    }

    /// The output keys (the `--json` keys and CSV columns), inputs first.
    pub fn keys(self) -> &'static [&'static str] {
        match self {
            Verb::Ik => &["x", "y", "z", "q1", "q2", "q3", "phi", "theta", "q4"],
            Verb::Fk => &[
                "q1",
                "q2",
                "q3",
                "x",
                "y",
                "z",
                "phi",
                "theta",
                "q4",
                "condition",
                "iterations",
            ],
            Verb::ToolIk => &[
                "x",
                "y",
                "z",
                "ax",
                "ay",
                "az",
                "q1",
                "q2",
                "q3",
                "phi",
                "theta",
                "q4",
                "h1",
                "h2",
                "head_singular",
            ],
        }
    }

    /// The unit of each key (for text output; empty when it has none).
    pub fn units(self) -> &'static [&'static str] {
        match self {
            Verb::Ik => &["mm", "mm", "mm", "mm", "mm", "mm", "rad", "rad", "mm"],
            Verb::Fk => &[
                "mm", "mm", "mm", "mm", "mm", "mm", "rad", "rad", "mm", "", "",
            ],
            Verb::ToolIk => &[
                "mm", "mm", "mm", "", "", "", "mm", "mm", "mm", "rad", "rad", "mm", "rad", "rad",
                "",
            ],
        }
    }

    /// The verb's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Verb::Ik => "ik",
            Verb::Fk => "fk",
            Verb::ToolIk => "tool-ik",
        }
    }

    /// Solves one point: `input` in the order of [`Verb::inputs`], the
    /// result in the order of [`Verb::keys`].
    pub fn solve(
        self,
        machine: &ExtendedMachine,
        input: &[f64],
    ) -> Result<Vec<Cell>, KinematicsError> {
        let n = Cell::Num;
        match self {
            Verb::Ik => {
                let sol = machine.inverse(&Vector3::new(input[0], input[1], input[2]))?;
                let (q, up) = (sol.legs_mm, sol.up);
                Ok(vec![
                    n(input[0]),
                    n(input[1]),
                    n(input[2]),
                    n(q[0]),
                    n(q[1]),
                    n(q[2]),
                    n(up.phi_rad),
                    n(up.theta_rad),
                    n(up.q4_mm),
                ])
            }
            Verb::Fk => {
                let sol = machine.forward(&[input[0], input[1], input[2]])?;
                let (p, up) = (sol.position_mm, sol.up);
                Ok(vec![
                    n(input[0]),
                    n(input[1]),
                    n(input[2]),
                    n(p.x),
                    n(p.y),
                    n(p.z),
                    n(up.phi_rad),
                    n(up.theta_rad),
                    n(up.q4_mm),
                    n(sol.condition),
                    Cell::Int(sol.iterations),
                ])
            }
            Verb::ToolIk => {
                let sol = machine.tool_inverse(
                    &Vector3::new(input[0], input[1], input[2]),
                    &Vector3::new(input[3], input[4], input[5]),
                    HeadBranch::default(),
                )?;
                let (q, up) = (sol.legs_mm, sol.up);
                let mut v: Vec<Cell> = input.iter().map(|x| n(*x)).collect();
                v.extend([
                    n(q[0]),
                    n(q[1]),
                    n(q[2]),
                    n(up.phi_rad),
                    n(up.theta_rad),
                    n(up.q4_mm),
                    n(sol.head_rad[0]),
                    n(sol.head_rad[1]),
                    Cell::Bool(sol.head_singular),
                ]);
                Ok(v)
            }
        }
    }
}

/// Why a batch stopped.
#[derive(Debug, Clone, PartialEq)]
pub enum BatchError {
    /// The input is not a valid CSV of the verb's columns.
    Input(String),
    /// A point could not be solved (out of reach, no assembly...).
    Point {
        /// Its line in the input.
        line: u64,
        /// What failed.
        source: KinematicsError,
    },
    /// Writing the output failed.
    Output(String),
}

impl std::fmt::Display for BatchError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BatchError::Input(m) | BatchError::Output(m) => f.write_str(m),
            BatchError::Point { line, source } => write!(f, "line {line}: {source}"),
        }
    }
}

fn write_cell(out: &mut Vec<u8>, c: Cell) {
    // Writing into a Vec cannot fail. Numbers are written in the shortest
    // form that reads back to the same bits, with an exponent for tiny and
    // huge magnitudes (`-9.47e-15`, not 15 zeros).
    let _ = match c {
        Cell::Num(x) if x != 0.0 && !(1e-5..1e15).contains(&x.abs()) => write!(out, "{x:e}"),
        Cell::Num(x) => write!(out, "{x}"),
        Cell::Int(i) => write!(out, "{i}"),
        Cell::Bool(b) => write!(out, "{b}"),
    };
}

/// Runs `verb` on every row of `input` (`file` names it in errors) and
/// writes the CSV to `out`; `stop` is asked between blocks (a closed
/// stdout). Returns the number of rows written.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{Machine, Verb, run};
/// let m = Machine::paper();
/// let m = m.extended();
/// let mut out = Vec::new();
/// let n = run(Verb::Ik, &m, "x,y,z\n0,0,750\n".as_bytes(), "points.csv", &mut out, || false).unwrap();
/// assert_eq!(n, 1);
/// let text = String::from_utf8(out).unwrap();
/// assert!(text.starts_with("x,y,z,q1,q2,q3,phi,theta,q4\n0,0,750,773.3"));
/// ```
pub fn run<R: Read, W: Write>(
    verb: Verb,
    machine: &ExtendedMachine,
    input: R,
    file: &str,
    mut out: W,
    stop: impl Fn() -> bool,
) -> Result<usize, BatchError> {
    let io = |e: std::io::Error| BatchError::Output(e.to_string());
    let mut written = 0;
    // The header goes out with the first block: an input without rows
    // prints nothing and is an error.
    let header = verb.keys().join(",") + "\n";
    let input_error = |e: tricept_data::DataError| BatchError::Input(e.to_string());
    match verb {
        Verb::Ik => {
            let rows = NumericRows::new(input, file, ["x", "y", "z"]).map_err(input_error)?;
            stream(verb, machine, rows, &header, &mut out, &stop, &mut written)?;
        }
        Verb::Fk => {
            let rows = NumericRows::new(input, file, ["q1", "q2", "q3"]).map_err(input_error)?;
            stream(verb, machine, rows, &header, &mut out, &stop, &mut written)?;
        }
        Verb::ToolIk => {
            let rows = NumericRows::new(input, file, ["x", "y", "z", "ax", "ay", "az"])
                .map_err(input_error)?;
            stream(verb, machine, rows, &header, &mut out, &stop, &mut written)?;
        }
    }
    out.flush().map_err(io)?;
    if written == 0 {
        return Err(BatchError::Input(format!(
            "{file}: header only, no data rows"
        )));
    }
    Ok(written)
}

fn stream<const N: usize, R: Read, W: Write>(
    verb: Verb,
    machine: &ExtendedMachine,
    mut rows: NumericRows<'_, R, N>,
    header: &str,
    out: &mut W,
    stop: &impl Fn() -> bool,
    written: &mut usize,
) -> Result<(), BatchError> {
    let mut block: Vec<(u64, [f64; N])> = Vec::with_capacity(BLOCK_ROWS);
    let mut text: Vec<u8> = Vec::with_capacity(BLOCK_ROWS * 160);
    loop {
        block.clear();
        let mut read_error = None;
        for row in rows.by_ref() {
            match row {
                Ok(r) => block.push(r),
                Err(e) => {
                    read_error = Some(BatchError::Input(e.to_string()));
                    break;
                }
            }
            if block.len() == BLOCK_ROWS {
                break;
            }
        }
        // Each row's text, solved in parallel, joined in order.
        let solved: Vec<Result<Vec<u8>, BatchError>> = block
            .par_iter()
            .map(|(line, input)| {
                let cells = verb
                    .solve(machine, input)
                    .map_err(|source| BatchError::Point {
                        line: *line,
                        source,
                    })?;
                let mut s = Vec::with_capacity(160);
                for (k, c) in cells.into_iter().enumerate() {
                    if k > 0 {
                        s.push(b',');
                    }
                    write_cell(&mut s, c);
                }
                s.push(b'\n');
                Ok(s)
            })
            .collect();
        text.clear();
        if *written == 0 && !block.is_empty() {
            text.extend_from_slice(header.as_bytes());
        }
        let mut failed = None;
        for r in solved {
            match r {
                Ok(s) => {
                    text.extend_from_slice(&s);
                    *written += 1;
                }
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
        }
        out.write_all(&text)
            .map_err(|e| BatchError::Output(e.to_string()))?;
        if let Some(e) = failed.or(read_error) {
            return Err(e);
        }
        if block.len() < BLOCK_ROWS || stop() {
            return Ok(());
        }
    }
}

/// Runs `verb` on every row of `input` ([`run`]) as the CLI does:
/// `file` names the input in its messages, `label` in the message of a
/// point that cannot be solved (`VERB --input LABEL: line N: ...`, of that
/// error's kind); a failed write is an error of kind other naming stdout.
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
        BatchError::Point { line, source } => Error::with_context(
            format!("{} --input {label}: line {line}", verb.name()),
            &source,
        ),
        BatchError::Output(message) => Error::other(format!("stdout: {message}")),
    })
}

/// One point solved by a kinematics verb.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSolution {
    verb: Verb,
    cells: Vec<Cell>,
}

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
/// assert!(s.to_json().starts_with(r#"{"x":0.0,"y":0.0,"z":750.0,"q1":773.3"#));
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
        .map_err(|e| Error::with_context(verb.name(), &e))?;
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

    /// The solution as one JSON object, the verb's keys in order.
    pub fn to_json(&self) -> String {
        let map: Map<String, Value> = self
            .verb
            .keys()
            .iter()
            .zip(&self.cells)
            .map(|(k, c)| (k.to_string(), c.to_json()))
            .collect();
        Value::Object(map).to_string()
    }

    /// The solution as aligned `key = value unit` lines.
    pub fn to_text(&self) -> String {
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
    lines.push("  (tricept machine --json prints the description file)".to_string());
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
        let v: Value = serde_json::from_str(&fk.to_json()).unwrap();
        for (k, want) in [("x", 100.0), ("y", -50.0), ("z", 760.0)] {
            assert!((v[k].as_f64().unwrap() - want).abs() < 1e-6, "{k}");
        }
        let text = ik.to_text();
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
            e.message().starts_with("ik --input -: line 3: "),
            "{}",
            e.message()
        );
        assert_eq!(String::from_utf8(out).unwrap().lines().count(), 2);
    }
}
