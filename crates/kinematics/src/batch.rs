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
//!
//! A batch runs on any [`PointKinematics`]: the exact [`Machine`], or a
//! machine with its leg effects applied (`tricept_model::ExtendedMachine`).

use std::io::{Read, Write};

use nalgebra::Vector3;
use rayon::prelude::*;
use tricept_data::targets::NumericRows;

use crate::{
    KinematicsError, Machine, fk::FkSolution, head::HeadBranch, head::ToolIkSolution,
    machine::IkSolution,
};

/// The three solutions a batch asks a machine for.
pub trait PointKinematics: Sync {
    /// Platform point (mm) to leg commands and UP joints.
    fn inverse(&self, r: &Vector3<f64>) -> Result<IkSolution, KinematicsError>;
    /// Leg commands (mm) to the UP joints and the platform point.
    fn forward(&self, commands_mm: &[f64; 3]) -> Result<FkSolution, KinematicsError>;
    /// Tool tip (mm) and axis to commands and head angles.
    fn tool_inverse(
        &self,
        tip_mm: &Vector3<f64>,
        axis: &Vector3<f64>,
        branch: HeadBranch,
    ) -> Result<ToolIkSolution, KinematicsError>;
}

impl PointKinematics for Machine {
    fn inverse(&self, r: &Vector3<f64>) -> Result<IkSolution, KinematicsError> {
        Machine::inverse(self, r)
    }
    fn forward(&self, commands_mm: &[f64; 3]) -> Result<FkSolution, KinematicsError> {
        Machine::forward(self, commands_mm)
    }
    fn tool_inverse(
        &self,
        tip_mm: &Vector3<f64>,
        axis: &Vector3<f64>,
        branch: HeadBranch,
    ) -> Result<ToolIkSolution, KinematicsError> {
        Machine::tool_inverse(self, tip_mm, axis, branch)
    }
}

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
    pub fn solve<K: PointKinematics + ?Sized>(
        self,
        machine: &K,
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
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_kinematics::Machine;
use tricept_kinematics::batch::{Verb, run};
let m = Machine::paper();
let mut out = Vec::new();
let n = run(Verb::Ik, &m, "x,y,z\n0,0,750\n".as_bytes(), "points.csv", &mut out, || false).unwrap();
assert_eq!(n, 1);
let text = String::from_utf8(out).unwrap();
assert!(text.starts_with("x,y,z,q1,q2,q3,phi,theta,q4\n0,0,750,773.3"));
```
"#
)]
pub fn run<K: PointKinematics + ?Sized, R: Read, W: Write>(
    verb: Verb,
    machine: &K,
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

fn stream<const N: usize, K: PointKinematics + ?Sized, R: Read, W: Write>(
    verb: Verb,
    machine: &K,
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
