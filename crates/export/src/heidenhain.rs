//! Heidenhain: nonlinear axis error compensation, one `*.COM` table per
//! leg axis and the `*.CMA` file that assigns them, and the backlash
//! (`MP_backLash`).
//!
//! A `*.COM` table holds the compensation points in its `AXISPOS` column
//! (mm, from the machine datum) and the values (mm) in the column named
//! after the axis (`[axis] = F(axis)`: a leadscrew error); the control
//! interpolates linearly between the points. The value is the axis'
//! **error**, as HEIDENHAIN enters it ("the axis-error is entered, with
//! the correct sign ... The error is positive if the table travel is too
//! long"; the nonlinear tables are the measured "error curve", plotted as
//! "Error in Z \[mm\]"): how much longer the leg is than its position says,
//! `+E`, the same sign as Sinumerik's table. A table is fixed-width: a
//! field runs from its column name's first character to the next name's,
//! so every value is written left-aligned under its name. The `*.CMA`
//! table has a column per compensated axis holding its `*.COM` file and
//! `*` in its `ACTIVE` column. Sources in docs/controllers.md.

use crate::linear::{self, LinearTable};
use crate::setup::{ControlFiles, Setup};

/// Decimals of the values and positions written, mm (0.1 um).
pub const DECIMALS: usize = 4;

/// The Heidenhain files of `setup`: a `*.COM` table per axis, the
/// `*.CMA` assignment, the machine parameters, and the parameters to set.
pub(crate) fn files(setup: &Setup) -> ControlFiles {
    let resolution = 10f64.powi(-(DECIMALS as i32));
    let (tables, mut out) = linear::plan_axes(setup, resolution, "the points a *.COM table takes");
    let names = &setup.names;
    for (t, ax) in tables.iter().zip(names) {
        out.files.push((com_name(ax), com_table(t, ax)));
    }
    out.files.push((CMA_NAME.to_string(), cma_table(names)));
    out.files.push((
        "MACHINE_PARAMETERS.TXT".to_string(),
        machine_parameters(names, &setup.backlash_mm),
    ));
    for (i, ax) in names.iter().enumerate() {
        out.parameters.push(format!(
            "{ax}: MP_backLash = {:.4} mm; {} active in {CMA_NAME}",
            setup.backlash_mm[i],
            com_name(ax),
        ));
    }
    out
}

/// The `*.COM` file name of axis `axis`.
pub fn com_name(axis: &str) -> String {
    format!("TRICEPT_{axis}.COM")
}

/// The `*.CMA` file name.
pub const CMA_NAME: &str = "TRICEPT.CMA";

/// The `*.COM` table of one axis: the error `+E` at each point, in
/// fixed-width columns (each value starts under its name's first
/// character and ends before the next name's).
pub fn com_table(t: &LinearTable, axis: &str) -> String {
    let rows: Vec<[String; 3]> = t
        .values_mm
        .iter()
        .enumerate()
        .map(|(n, v)| {
            let pos = t.start_mm + t.step_mm * n as f64;
            [
                n.to_string(),
                format!("{pos:+.DECIMALS$}"),
                // (-0.0 + 0.0 is +0.0: no "-0.0000".)
                format!("{:+.DECIMALS$}", v + 0.0),
            ]
        })
        .collect();
    let names = ["NR", "AXISPOS", axis];
    // Each column one wider than its longest field: a blank always
    // separates two fields.
    let widths: [usize; 3] = std::array::from_fn(|c| {
        rows.iter()
            .map(|r| r[c].len())
            .chain([names[c].len()])
            .max()
            .unwrap_or(0)
            + 1
    });
    let line = |fields: [&str; 3]| {
        let mut l = String::new();
        for (f, w) in fields.iter().zip(widths) {
            l.push_str(&format!("{f:<w$}"));
        }
        l.truncate(l.trim_end().len());
        l.push('\n');
        l
    };
    let mut s = format!("BEGIN {} MM\n", com_name(axis));
    s.push_str(&line(names));
    for r in &rows {
        s.push_str(&line([&r[0], &r[1], &r[2]]));
    }
    s.push_str("[END]\n");
    s
}

/// The `*.CMA` assignment of the three axes, active.
pub fn cma_table(names: &[String]) -> String {
    let mut s = format!("BEGIN {CMA_NAME}\n{:<6}{:<8}", "NR", "ACTIVE");
    for ax in names {
        s.push_str(&format!("{ax:<20}"));
    }
    s.push_str(&format!("\n{:<6}{:<8}", 0, "*"));
    for ax in names {
        s.push_str(&format!("{:<20}", com_name(ax)));
    }
    s.push_str("\n[END]\n");
    s
}

/// The machine parameters to set: the backlash of each axis, mm.
pub fn machine_parameters(names: &[String], backlash_mm: &[f64; 3]) -> String {
    let mut s = String::from("; tricept export: machine parameters of the Tricept legs\n");
    for (ax, b) in names.iter().zip(backlash_mm) {
        s.push_str(&format!("{ax}: MP_backLash = {b:.DECIMALS$}\n"));
    }
    s
}
