//! A leg's correction resampled into an absolute table read by linear
//! interpolation between equally spaced points, the end values holding
//! beyond them: the shape of Sinumerik's `$AA_ENC_COMP` and Heidenhain's
//! `*.COM` tables.
//!
//! The grid is the deployed table's own (extended over the stroke) when
//! the control takes that many points, so that the written table is the
//! deployed one; else the stroke is resampled on the most points the
//! control takes and the cost is measured: [`LinearTable::format_error_um`]
//! is the largest difference between the written table, read the way the
//! control reads it (rounded values included), and the exact correction,
//! over the stroke.

use crate::correction::LegCorrection;
use crate::setup::{ControlFiles, Deviation, Setup};

/// Spacing of a table for a leg without a compensation table (a lead
/// error alone is linear: any spacing is exact), mm.
pub const PLAIN_STEP_MM: f64 = 10.0;

/// Check points per grid cell when a table's error is measured.
const CHECKS_PER_CELL: usize = 8;

/// A resampled absolute table.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearTable {
    /// Axis position of the first point, mm.
    pub start_mm: f64,
    /// Spacing of the points, mm.
    pub step_mm: f64,
    /// The leg's extra length at each point relative to the reference
    /// point, mm, rounded to the control's resolution.
    pub values_mm: Vec<f64>,
    /// The constant taken out of the values so that the table reads zero
    /// at the reference point (added to the leg's zero), mm.
    pub shift_mm: f64,
    /// Points the deployed table's own spacing would need over the stroke
    /// (what to raise the point limit to for an exact table).
    pub points_needed: usize,
    /// Largest difference between the table as read and the exact
    /// correction over the stroke, um.
    pub format_error_um: f64,
}

impl LinearTable {
    /// The table read at `q_mm` by linear interpolation, the end values
    /// beyond the points, mm.
    pub fn read_mm(&self, q_mm: f64) -> f64 {
        read_linear(self.start_mm, self.step_mm, &self.values_mm, q_mm)
    }

    /// The axis position the control settles at for setpoint `p_mm`: it
    /// corrects the position by the table's value there, so the axis
    /// stops where `x + table(x) = p`.
    pub fn motor_mm(&self, p_mm: f64) -> f64 {
        crate::correction::settle(p_mm, |x| self.read_mm(x))
    }

    /// Where the control leaves the axis minus where the machine file asks
    /// for it, mm, at the exact command `q_mm` (the setpoint the PKM
    /// transformation sends for it, through the control).
    pub fn deviation_mm(&self, leg: &LegCorrection, q_mm: f64) -> f64 {
        self.motor_mm(leg.setpoint_mm(q_mm, self.shift_mm)) - q_mm
    }

    /// Position of the last point, mm.
    pub fn end_mm(&self) -> f64 {
        self.start_mm + self.step_mm * self.values_mm.len().saturating_sub(1) as f64
    }
}

/// Linear interpolation of `values` at `start + k step`, the end values
/// beyond them (zero for no values).
fn read_linear(start_mm: f64, step_mm: f64, values: &[f64], q_mm: f64) -> f64 {
    let Some(last) = values.len().checked_sub(1) else {
        return 0.0;
    };
    if last == 0 {
        return values[0];
    }
    let x = ((q_mm - start_mm) / step_mm).clamp(0.0, last as f64);
    let k = (x.floor() as usize).min(last - 1);
    let f = x - k as f64;
    values[k] + f * (values[k + 1] - values[k])
}

/// Rounds `v` to a multiple of `resolution`.
fn round_to(v: f64, resolution: f64) -> f64 {
    (v / resolution).round() * resolution
}

/// `leg`'s correction as a linear table of at most `max_points` points,
/// its values, its first point and its spacing rounded to
/// `resolution_mm` (the decimals the control's file is written with: the
/// points lie where the control reads them, not a rounding away).
pub fn resample(leg: &LegCorrection, max_points: usize, resolution_mm: f64) -> LinearTable {
    let (lo, hi) = (leg.lo_mm, leg.hi_mm);
    let stroke = hi - lo;
    // The deployed table's own grid, extended to cover the stroke.
    let (start, step, points_needed) = match &leg.table {
        Some(t) if t.step_mm > 0.0 => {
            let below = ((t.start_mm - lo) / t.step_mm).ceil();
            let start = t.start_mm - below * t.step_mm;
            let n = ((hi - start) / t.step_mm).ceil() as usize + 1;
            (start, t.step_mm, n)
        }
        _ => {
            let n = (stroke / PLAIN_STEP_MM).ceil() as usize + 1;
            (lo, stroke / (n - 1) as f64, n)
        }
    };
    let (start, step) = if points_needed <= max_points {
        (start, step)
    } else {
        let n = max_points.max(2);
        (lo, stroke / (n - 1) as f64)
    };
    // As written: the spacing to the resolution, the first point at or
    // below the stroke's start.
    let mut start = round_to(start, resolution_mm);
    if start > lo {
        start -= resolution_mm;
    }
    let points = |step: f64| (((hi - start) / step - 1e-9).ceil() as usize + 1).max(2);
    let mut step = round_to(step, resolution_mm).max(resolution_mm);
    // Rounded down, the spacing may need one point more than the control
    // takes: then the next one up.
    while points(step) > max_points.max(2) {
        step += resolution_mm;
    }
    let n = points(step);
    let exact: Vec<f64> = (0..n)
        .map(|k| leg.relative_mm(start + step * k as f64))
        .collect();
    // Zero at the reference point as read (the values are shifted by a
    // constant: linear interpolation shifts by the same constant).
    let shift_mm = read_linear(start, step, &exact, leg.reference_mm);
    let values_mm: Vec<f64> = exact
        .iter()
        .map(|v| round_to(v - shift_mm, resolution_mm))
        .collect();
    let mut table = LinearTable {
        start_mm: start,
        step_mm: step,
        values_mm,
        shift_mm,
        points_needed,
        format_error_um: 0.0,
    };
    // Over every point's span, not only the stroke: the summary states the
    // span.
    let span = LegCorrection {
        lo_mm: start,
        hi_mm: table.end_mm(),
        ..leg.clone()
    };
    table.format_error_um = span
        .check_points_mm(start, step, CHECKS_PER_CELL)
        .into_iter()
        .map(|q| table.deviation_mm(leg, q).abs() * 1e3)
        .fold(0.0, f64::max);
    table
}

/// The three legs of `setup` as linear tables rounded to `resolution_mm`,
/// with their axes' summaries, how they leave the legs, and the limits
/// past the tolerance (naming the control's point limit, `points_limit`):
/// the part of [`ControlFiles`] the two linear formats share.
pub(crate) fn plan_axes(
    setup: &Setup,
    resolution_mm: f64,
    points_limit: &str,
) -> (Vec<LinearTable>, ControlFiles) {
    let tables: Vec<LinearTable> = setup
        .legs
        .iter()
        .map(|l| resample(l, setup.max_points, resolution_mm))
        .collect();
    let mut out = ControlFiles {
        files: Vec::new(),
        axes: Vec::new(),
        parameters: Vec::new(),
        limits: Vec::new(),
        carries_thermal: false,
        readings: vec![std::array::from_fn(|i| {
            let (t, l) = (tables[i].clone(), setup.legs[i].clone());
            Box::new(move |q| t.deviation_mm(&l, q)) as Deviation
        })],
    };
    for (i, t) in tables.iter().enumerate() {
        out.axes.push(setup.axis_summary(
            i,
            t.values_mm.len(),
            t.step_mm,
            (t.start_mm, t.end_mm()),
            t.format_error_um,
            t.shift_mm,
        ));
        if t.format_error_um > setup.options.tolerance_um {
            out.limits.push(format!(
                "axis {}: format error {:.3} um past tolerance_um {}: raise max_points ({points_limit}) to {} (the deployed table's own spacing)",
                setup.names[i], t.format_error_um, setup.options.tolerance_um, t.points_needed
            ));
        }
    }
    (tables, out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tricept_kinematics::description::LegTableDescription;

    fn leg(table: Option<LegTableDescription>) -> LegCorrection {
        LegCorrection {
            leg: 0,
            lead_ppm: 50.0,
            table,
            reference_mm: 800.0,
            lo_mm: 640.0,
            hi_mm: 1040.0,
        }
    }

    #[test]
    fn a_lead_error_alone_is_exact_and_zero_at_the_reference() {
        let t = resample(&leg(None), 200, 1e-6);
        assert!(t.format_error_um < 0.002, "{}", t.format_error_um);
        assert!(t.read_mm(800.0).abs() < 1e-6);
        // 50 ppm over 200 mm above the reference: 10 um.
        assert!((t.read_mm(1000.0) - 0.010).abs() < 1e-6);
    }

    #[test]
    fn a_table_that_fits_is_kept_and_one_that_does_not_costs_its_error() {
        // A 4 um sine of period 10 mm on 0.5 mm points.
        let values: Vec<f64> = (0..801)
            .map(|k| 4.0 * (std::f64::consts::TAU * k as f64 * 0.5 / 10.0).sin())
            .collect();
        let table = LegTableDescription::new(1, 640.0, 0.5, values);
        let fits = resample(&leg(Some(table.clone())), 1000, 1e-6);
        assert_eq!(fits.points_needed, 801);
        assert!(fits.format_error_um < 0.002, "{}", fits.format_error_um);
        let coarse = resample(&leg(Some(table)), 200, 1e-6);
        assert_eq!(coarse.values_mm.len(), 200);
        // Linear interpolation over ~2 mm of a 10 mm period: about
        // A (1 - cos(pi h / P)) = 0.76 um.
        assert!(
            coarse.format_error_um > 0.3 && coarse.format_error_um < 1.5,
            "{}",
            coarse.format_error_um
        );
    }

    #[test]
    fn a_table_s_grid_is_extended_to_cover_the_stroke() {
        // Points every 0.5 mm from 641.3 mm: extended down to the first
        // point of that grid at or below the stroke's 640 mm, 639.8 mm.
        let table = LegTableDescription::new(1, 641.3, 0.5, vec![0.0; 700]);
        let t = resample(&leg(Some(table)), 10_000, 1e-6);
        assert!((t.start_mm - 639.8).abs() < 1e-9, "{}", t.start_mm);
        assert_eq!(t.step_mm, 0.5);
        // Up to the first point at or above 1040 mm: 1040.3 mm.
        assert!((t.end_mm() - 1040.3).abs() < 1e-9, "{}", t.end_mm());
        assert_eq!(t.points_needed, t.values_mm.len());
    }

    #[test]
    fn without_a_table_the_points_are_at_most_the_plain_step_apart() {
        for table in [
            None,
            // A table without a spacing is no grid to keep.
            Some(LegTableDescription::new(1, 640.0, 0.0, vec![0.0; 3])),
        ] {
            let t = resample(&leg(table), 200, 1e-6);
            // 400 mm of stroke: 41 points, 10 mm apart.
            assert_eq!(t.start_mm, 640.0);
            assert_eq!(t.values_mm.len(), 41);
            assert!((t.step_mm - PLAIN_STEP_MM).abs() < 1e-12, "{}", t.step_mm);
            assert_eq!(t.points_needed, 41);
        }
    }

    #[test]
    fn the_table_reads_zero_at_a_reference_between_its_points() {
        // A 4 um sine of period 10 mm on 0.5 mm points; the reference at
        // 800.2 mm.
        let values: Vec<f64> = (0..801)
            .map(|k| 4.0 * (std::f64::consts::TAU * k as f64 * 0.5 / 10.0).sin())
            .collect();
        let mut l = leg(Some(LegTableDescription::new(1, 640.0, 0.5, values)));
        l.reference_mm = 800.2;
        // Resampled on 200 points (2 mm apart): the exact correction read
        // at the reference between them is not zero.
        let t = resample(&l, 200, 1e-6);
        assert!(t.shift_mm.abs() > 1e-5, "{}", t.shift_mm);
        assert!(t.read_mm(800.2).abs() <= 1e-6, "{}", t.read_mm(800.2));
        // The format error is the largest miss of the table as read, found
        // here on a grid of 1 um.
        let mut largest: f64 = 0.0;
        for j in 0..=400_000 {
            let q = 640.0 + f64::from(j) * 1e-3;
            largest = largest.max((t.read_mm(q) - (l.relative_mm(q) - t.shift_mm)).abs() * 1e3);
        }
        assert!(
            (t.format_error_um - largest).abs() < 2e-3,
            "{} um reported, {largest} um found",
            t.format_error_um
        );
        // Every point is the exact correction less the shift.
        for (k, v) in t.values_mm.iter().enumerate() {
            let q = t.start_mm + t.step_mm * k as f64;
            assert!((v - (l.relative_mm(q) - t.shift_mm)).abs() <= 0.5e-6 + 1e-12);
        }
    }
}
