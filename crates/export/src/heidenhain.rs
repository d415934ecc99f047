//! Heidenhain: nonlinear axis error compensation, one `*.COM` table per
//! leg axis and the `*.CMA` file that assigns them, and the backlash
//! (`MP_backLash`).
//!
//! A `*.COM` table holds the compensation points in its `AXISPOS` column
//! (mm, from the machine datum) and the compensation values (mm) in the
//! column named after the axis (`[axis] = F(axis)`: a leadscrew error);
//! the control interpolates linearly between the points. The value is the
//! compensation added to the axis' nominal position: the negated error.
//! The `*.CMA` table has a column per compensated axis holding its
//! `*.COM` file and `*` in its `ACTIVE` column. Sources in
//! docs/controllers.md.

use crate::linear::LinearTable;

/// Decimals of the values and positions written, mm (0.1 um).
pub const DECIMALS: usize = 4;

/// The `*.COM` file name of axis `axis`.
pub fn com_name(axis: &str) -> String {
    format!("TRICEPT_{axis}.COM")
}

/// The `*.CMA` file name.
pub const CMA_NAME: &str = "TRICEPT.CMA";

/// The `*.COM` table of one axis.
pub fn com_table(t: &LinearTable, axis: &str) -> String {
    let mut s = format!("BEGIN {} MM\n", com_name(axis));
    s.push_str(&format!("{:<6}{:>14}{:>14}\n", "NR", "AXISPOS", axis));
    for (n, v) in t.values_mm.iter().enumerate() {
        let pos = t.start_mm + t.step_mm * n as f64;
        s.push_str(&format!(
            "{n:<6}{pos:>+14.DECIMALS$}{:>+14.DECIMALS$}\n",
            -v
        ));
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
