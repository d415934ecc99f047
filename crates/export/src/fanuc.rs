//! Fanuc: pitch error compensation (parameters 3620-3624 per axis, the
//! values as pitch error compensation data `N10000+n P..`) and backlash
//! (parameter 1851), in detection units.
//!
//! How the control reads it (docs/controllers.md, with the sources): the
//! points are numbered, point `n` at `P_n = P_ref + (n - n_ref) h` with
//! `n_ref` (3620) the point of the reference position and `h` (3624) the
//! interval; the value of point `n` is the *increment* of the compensation
//! over the section from `P_(n-1)` to `P_n`, in detection units times the
//! magnification (3623); the compensation is output section by section (a
//! staircase, no interpolation), zero in the reference position's own
//! section, and added to the commanded position.

use crate::correction::LegCorrection;

/// Check points per section when a table's error is measured.
const CHECKS_PER_SECTION: usize = 16;

/// The largest magnification parameter 3623 takes.
pub const MAX_MAGNIFICATION: u32 = 100;

/// One axis' pitch error compensation.
#[derive(Debug, Clone, PartialEq)]
pub struct FanucAxis {
    /// Number of the point of the reference position (3620).
    pub reference_point: usize,
    /// Number of the farthest point on the negative side (3621).
    pub first_point: usize,
    /// Number of the farthest point on the positive side (3622).
    pub last_point: usize,
    /// Magnification (3623).
    pub magnification: u32,
    /// Interval of the points (3624), detection units.
    pub interval_units: u64,
    /// The interval, mm.
    pub interval_mm: f64,
    /// The position of the reference point, mm.
    pub reference_mm: f64,
    /// The value of each point from `first_point` to `last_point`
    /// (increments, in detection units times the magnification).
    pub increments: Vec<i64>,
    /// Whether an increment had to be clipped to the range a point takes
    /// (the magnification is at its largest).
    pub clipped: bool,
    /// The constant taken out of the correction so that the reference
    /// position's own section reads zero (added to the leg's zero), mm.
    pub shift_mm: f64,
    /// Largest difference between the compensation as output and the
    /// exact correction, over the stroke, um.
    pub format_error_um: f64,
}

impl FanucAxis {
    /// The compensation output at commanded position `q_mm` (mm, added to
    /// the command): the staircase of the accumulated increments.
    pub fn output_mm(&self, q_mm: f64, detection_unit_um: f64) -> f64 {
        self.staircase(detection_unit_um).output_mm(q_mm)
    }

    /// The leg's length as the control leaves it at command `q_mm` minus
    /// the exact one, mm: the output is added to the command, which the
    /// exact correction wants shortened by `E(q) - E(q_ref)` less the
    /// shift.
    pub fn deviation_mm(&self, leg: &LegCorrection, q_mm: f64, detection_unit_um: f64) -> f64 {
        self.staircase(detection_unit_um).deviation_mm(leg, q_mm)
    }

    /// The staircase the control outputs, each section's accumulated
    /// increments summed once: for the many check points at which a
    /// table's error is measured.
    pub(crate) fn staircase(&self, detection_unit_um: f64) -> Staircase {
        // The points from the first (3621) on, one increment each.
        let lo = self.first_point as i64 - self.reference_point as i64;
        let first = accumulated(&self.increments, lo, lo);
        let above = (lo + 1..lo + self.increments.len() as i64).scan(first, |level, k| {
            *level += increment(&self.increments, lo, k);
            Some(*level)
        });
        Staircase {
            lo,
            reference_mm: self.reference_mm,
            interval_mm: self.interval_mm,
            unit_mm: f64::from(self.magnification) * detection_unit_um * 1e-3,
            shift_mm: self.shift_mm,
            accumulated: std::iter::once(first).chain(above).collect(),
        }
    }
}

/// An axis' output: each section's accumulated increments (in units of
/// `unit_mm`), from section `lo` (the first point's) on; beyond either
/// end the end's.
#[derive(Debug, Clone)]
pub(crate) struct Staircase {
    lo: i64,
    reference_mm: f64,
    interval_mm: f64,
    unit_mm: f64,
    shift_mm: f64,
    accumulated: Vec<i64>,
}

impl Staircase {
    /// [`FanucAxis::output_mm`].
    pub(crate) fn output_mm(&self, q_mm: f64) -> f64 {
        let k = section(q_mm, self.reference_mm, self.interval_mm);
        let index = (k - self.lo).clamp(0, self.accumulated.len() as i64 - 1);
        self.accumulated.get(index as usize).copied().unwrap_or(0) as f64 * self.unit_mm
    }

    /// [`FanucAxis::deviation_mm`].
    pub(crate) fn deviation_mm(&self, leg: &LegCorrection, q_mm: f64) -> f64 {
        self.output_mm(q_mm) + (leg.relative_mm(q_mm) - self.shift_mm)
    }
}

/// The section (relative to the reference point's) that holds `q`: the
/// section `k` runs from `P_ref + (k - 1) h` (excluded) to `P_ref + k h`.
fn section(q_mm: f64, reference_mm: f64, interval_mm: f64) -> i64 {
    ((q_mm - reference_mm) / interval_mm - 1e-12).ceil() as i64
}

/// The value of point `j` (relative numbering, the first point at `lo`;
/// 0 beyond the points): the increment over the section up to it.
fn increment(increments: &[i64], lo: i64, j: i64) -> i64 {
    increments.get((j - lo) as usize).copied().unwrap_or(0)
}

/// The accumulated compensation of section `k` (relative numbering, the
/// first point at `lo`): the sum of the increments from the reference
/// point outwards.
fn accumulated(increments: &[i64], lo: i64, k: i64) -> i64 {
    let at = |j: i64| increment(increments, lo, j);
    if k >= 0 {
        (1..=k).map(at).sum()
    } else {
        -(k + 1..=0).map(at).sum::<i64>()
    }
}

/// `leg`'s correction as Fanuc pitch error compensation on at most
/// `max_points` points, numbered from `first_number`, in detection units
/// of `detection_unit_um` with increments of at most `max_increment`.
pub fn plan(
    leg: &LegCorrection,
    max_points: usize,
    first_number: usize,
    detection_unit_um: f64,
    max_increment: u32,
) -> FanucAxis {
    let du_mm = detection_unit_um * 1e-3;
    let stroke = leg.hi_mm - leg.lo_mm;
    let interval_units = ((stroke / (max_points.max(3) - 2) as f64) / du_mm).ceil() as u64;
    let h = interval_units.max(1) as f64 * du_mm;
    let q_ref = leg.reference_mm;
    let k_lo = section(leg.lo_mm, q_ref, h);
    let k_hi = section(leg.hi_mm, q_ref, h);
    let midrange = |k: i64| {
        let (a, b) = (q_ref + (k - 1) as f64 * h, q_ref + k as f64 * h);
        let (lo, hi) = (0..=CHECKS_PER_SECTION)
            .map(|j| leg.relative_mm(a + (b - a) * j as f64 / CHECKS_PER_SECTION as f64))
            .chain(
                leg.knots_mm()
                    .into_iter()
                    .filter(|q| *q > a && *q <= b)
                    .map(|q| leg.relative_mm(q)),
            )
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        0.5 * (lo + hi)
    };
    let shift_mm = midrange(0);
    // The best staircase: each section at the middle of the correction's
    // range over it (negated: the compensation is added to the command).
    let target: Vec<f64> = (k_lo..=k_hi)
        .map(|k| {
            if k == 0 {
                0.0
            } else {
                -(midrange(k) - shift_mm)
            }
        })
        .collect();
    let mut chosen = None;
    for m in 1..=MAX_MAGNIFICATION {
        let unit = f64::from(m) * du_mm;
        let (increments, clipped) = increments_of(&target, k_lo, unit, max_increment);
        let last = m == MAX_MAGNIFICATION;
        if !clipped || last {
            chosen = Some((m, increments, clipped));
            break;
        }
    }
    let (magnification, increments, clipped) = chosen.unwrap_or((1, Vec::new(), true));
    let reference_point = first_number + (-k_lo) as usize;
    let mut axis = FanucAxis {
        reference_point,
        first_point: first_number,
        last_point: first_number + (k_hi - k_lo) as usize,
        magnification,
        interval_units,
        interval_mm: h,
        reference_mm: q_ref,
        increments,
        clipped,
        shift_mm,
        format_error_um: 0.0,
    };
    let start = q_ref + (k_lo - 1) as f64 * h;
    // The staircase steps at each section's end, which belongs to the
    // section below: the miss is checked at it and just above it (every
    // section's end inside the stroke; the first section's lower end lies
    // below it).
    let ends = (k_lo..k_hi).flat_map(|k| {
        let end = q_ref + k as f64 * h;
        [end, end + 1e-6]
    });
    let staircase = axis.staircase(detection_unit_um);
    axis.format_error_um = leg
        .check_points_mm(start, h, CHECKS_PER_SECTION)
        .into_iter()
        .chain(ends)
        .map(|q| staircase.deviation_mm(leg, q).abs() * 1e3)
        .fold(0.0, f64::max);
    axis
}

/// The increments (units of `unit_mm`) whose accumulation from the
/// reference section (index `-k_lo` of `target`) follows `target`
/// (mm), each within `max_increment` (clipped, and said so, when not).
fn increments_of(target: &[f64], k_lo: i64, unit_mm: f64, max_increment: u32) -> (Vec<i64>, bool) {
    let r = (-k_lo) as usize;
    let cap = i64::from(max_increment);
    let mut increments = vec![0i64; target.len()];
    let mut clipped = false;
    // Outwards from the reference: positive side, point k carries
    // A_k - A_(k-1); negative side, point k+1 carries A_(k+1) - A_k.
    let mut acc = 0i64;
    for j in r + 1..target.len() {
        let want = (target[j] / unit_mm).round() as i64;
        let v = (want - acc).clamp(-cap, cap);
        clipped |= v != want - acc;
        increments[j] = v;
        acc += v;
    }
    let mut acc = 0i64;
    for j in (0..r).rev() {
        let want = (target[j] / unit_mm).round() as i64;
        // A_j = A_(j+1) - v_(j+1).
        let v = (acc - want).clamp(-cap, cap);
        clipped |= v != acc - want;
        increments[j + 1] = v;
        acc -= v;
    }
    (increments, clipped)
}

/// The pitch error compensation data (`N10000+n P..`), every axis.
pub fn pitch_tape(axes: &[FanucAxis]) -> String {
    let mut s = String::from("%\n");
    for a in axes {
        for (j, v) in a.increments.iter().enumerate() {
            s.push_str(&format!("N{}P{v}\n", 10000 + a.first_point + j));
        }
    }
    s.push_str("%\n");
    s
}

/// The parameters (`N<number>A<axis>P<value>`): 1851 backlash, 3620-3624.
pub fn parameter_tape(axes: &[FanucAxis], backlash_units: &[i64; 3]) -> String {
    let row = |number: u32, values: Vec<String>| {
        let mut line = format!("N{number}");
        for (i, v) in values.iter().enumerate() {
            line.push_str(&format!("A{}P{v}", i + 1));
        }
        line.push('\n');
        line
    };
    let mut s = String::from("%\n");
    s.push_str(&row(
        1851,
        backlash_units.iter().map(i64::to_string).collect(),
    ));
    s.push_str(&row(
        3620,
        axes.iter().map(|a| a.reference_point.to_string()).collect(),
    ));
    s.push_str(&row(
        3621,
        axes.iter().map(|a| a.first_point.to_string()).collect(),
    ));
    s.push_str(&row(
        3622,
        axes.iter().map(|a| a.last_point.to_string()).collect(),
    ));
    s.push_str(&row(
        3623,
        axes.iter().map(|a| a.magnification.to_string()).collect(),
    ));
    s.push_str(&row(
        3624,
        axes.iter().map(|a| a.interval_units.to_string()).collect(),
    ));
    s.push_str("%\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use tricept_kinematics::description::LegTableDescription;

    /// A lead error of `ppm` on a leg of stroke 640 to 1040 mm, the
    /// reference at 800 mm.
    fn lead(ppm: f64) -> LegCorrection {
        LegCorrection {
            leg: 0,
            lead_ppm: ppm,
            table: None,
            reference_mm: 800.0,
            lo_mm: 640.0,
            hi_mm: 1040.0,
        }
    }

    #[test]
    fn a_lead_error_is_a_staircase_zero_in_the_reference_section() {
        let leg = lead(50.0);
        let a = plan(&leg, 128, 0, 1.0, 127);
        assert!(a.last_point - a.first_point < 128);
        assert_eq!(a.output_mm(800.0, 1.0), 0.0);
        // 50 ppm over a section of ~3.2 mm: a staircase misses by half a
        // step (0.08 um) plus half a detection unit.
        assert!(a.format_error_um < 0.6, "{}", a.format_error_um);
        // 200 mm above the reference the axis is 10 um long: -10 um.
        assert!((a.output_mm(1000.0, 1.0) + 0.010).abs() < 0.0006);
        assert!((a.output_mm(700.0, 1.0) - 0.005).abs() < 0.0006);
    }

    #[test]
    fn the_magnification_grows_until_each_increment_fits_and_clipping_is_said() {
        // 5000 ppm over ~3.2 mm sections: 16 um a section, 7 at the most:
        // magnification 3.
        let a = plan(&lead(5000.0), 128, 0, 1.0, 7);
        assert_eq!(a.magnification, 3);
        assert!(!a.clipped);
        assert!(a.increments.iter().all(|v| v.abs() <= 7));
        // 200 um a section cannot fit 1 x 100: clipped, and the error
        // says so.
        let b = plan(&lead(62_500.0), 128, 0, 1.0, 1);
        assert!(b.clipped);
        assert_eq!(b.magnification, MAX_MAGNIFICATION);
        assert!(b.format_error_um > 1000.0, "{}", b.format_error_um);
    }

    #[test]
    fn a_section_holds_its_upper_end_and_not_its_lower() {
        // Section k runs from P_ref + (k - 1) h (excluded) to P_ref + k h.
        assert_eq!(section(10.0, 0.0, 2.0), 5);
        assert_eq!(section(10.5, 0.0, 2.0), 6);
        assert_eq!(section(8.5, 0.0, 2.0), 5);
        assert_eq!(section(0.0, 0.0, 2.0), 0);
        assert_eq!(section(-2.0, 0.0, 2.0), -1);
        assert_eq!(section(-2.5, 0.0, 2.0), -1);
        // 803.2 - 800 is 3.2000000000000455 in floating point: still the
        // end of section 2 of 1.6 mm.
        assert_eq!(section(803.2, 800.0, 1.6), 2);
    }

    #[test]
    fn the_interval_is_the_stroke_over_the_sections_in_whole_detection_units() {
        // 10 mm on 12 points: 10 sections of 1 mm (a point is the
        // reference's, one the stroke's partial section).
        let leg = LegCorrection {
            leg: 0,
            lead_ppm: 0.0,
            table: None,
            reference_mm: 105.0,
            lo_mm: 100.0,
            hi_mm: 110.0,
        };
        let a = plan(&leg, 12, 0, 1.0, 127);
        assert_eq!((a.interval_units, a.interval_mm), (1000, 1.0));
        assert_eq!(plan(&leg, 12, 0, 0.1, 127).interval_units, 10_000);
        // 10 mm in 7 sections: 1.428... mm, rounded up to whole units.
        let c = plan(&leg, 9, 0, 1.0, 127);
        assert_eq!(c.interval_units, 1429);
        assert!((c.interval_mm - 1.429).abs() < 1e-12);
    }

    #[test]
    fn clipping_on_either_side_of_the_reference_is_said() {
        // Three sections, the reference's the middle one; 1 um units, at
        // most 3 a point. Above the reference point k carries A_k -
        // A_(k-1); below, point k + 1 carries A_(k+1) - A_k.
        assert_eq!(
            increments_of(&[-0.002, 0.0, 0.002], -1, 0.001, 3),
            (vec![0, 2, 2], false)
        );
        assert_eq!(
            increments_of(&[0.0, 0.0, 0.010], -1, 0.001, 3),
            (vec![0, 0, 3], true)
        );
        assert_eq!(
            increments_of(&[-0.010, 0.0, 0.0], -1, 0.001, 3),
            (vec![0, 3, 0], true)
        );
    }

    /// The largest miss of `a`'s staircase of `leg` (in detection units of
    /// `detection_unit_um`), searched on a grid of 1 um over 640 to 1040 mm
    /// and on either side of every section's end.
    fn largest_miss_um(a: &FanucAxis, leg: &LegCorrection, detection_unit_um: f64) -> f64 {
        let exact = |q: f64| -(leg.relative_mm(q) - a.shift_mm);
        let output = a.staircase(detection_unit_um);
        let miss = |q: f64| (output.output_mm(q) - exact(q)).abs() * 1e3;
        let mut largest: f64 = 0.0;
        for j in 0..=400_000 {
            largest = largest.max(miss(640.0 + f64::from(j) * 1e-3));
        }
        let first =
            a.reference_mm + (a.first_point as f64 - a.reference_point as f64) * a.interval_mm;
        for k in 0..=a.increments.len() {
            let end = first + a.interval_mm * k as f64;
            if (leg.lo_mm..=leg.hi_mm).contains(&end) {
                largest = largest.max(miss(end)).max(miss(end + 1e-9));
            }
        }
        largest
    }

    #[test]
    fn the_format_error_is_the_staircase_s_largest_miss() {
        // A lead error with the reference point off the grid of whole mm:
        // the format error is the largest difference between the staircase
        // (read back) and the exact correction, searched here on a grid of
        // 1 um and on either side of every section's end.
        let leg = LegCorrection {
            leg: 0,
            lead_ppm: 300.0,
            table: None,
            reference_mm: 800.37,
            lo_mm: 640.0,
            hi_mm: 1040.0,
        };
        // 100 points: sections of 4.0817 mm, whose ends a grid of 16
        // points a section started elsewhere misses by 0.05 mm or more.
        let a = plan(&leg, 100, 0, 0.1, 127);
        let largest = largest_miss_um(&a, &leg, 0.1);
        assert!(
            (a.format_error_um - largest).abs() < 2e-3,
            "{} um reported, {largest} um found",
            a.format_error_um
        );
        // A table rising 4 um/mm from 640 to 680 mm, flat above, the
        // reference near the bottom: the largest misses lie in the sections
        // of the rise (none at a knot).
        let mut values = vec![160.0; 11];
        values[0] = 0.0;
        let leg = LegCorrection {
            lead_ppm: 0.0,
            table: Some(LegTableDescription::new(1, 640.0, 40.0, values)),
            reference_mm: 660.37,
            ..leg
        };
        let a = plan(&leg, 100, 0, 0.1, 127);
        let largest = largest_miss_um(&a, &leg, 0.1);
        // Half of a section's rise, 4 um/mm over 4.0817 mm, and up to half
        // a unit (the magnification 2 keeps 16 um within 127 units of 0.1).
        assert_eq!(a.magnification, 2);
        assert!(
            (largest - 2.0 * a.interval_mm).abs() <= 0.1 + 1e-9,
            "{largest}"
        );
        assert!(
            (a.format_error_um - largest).abs() < 2e-3,
            "{} um reported, {largest} um found",
            a.format_error_um
        );
    }

    #[test]
    fn each_section_sits_at_the_middle_of_the_correction_s_range_knots_included() {
        // A deployed table zero but for a 10 um spike at one point, between
        // the 16 samples of its section (sections of 4.0817 mm from the
        // reference 800.37 mm, samples 0.2551 mm apart; the spike 0.02 mm
        // wide, 0.127 mm from the nearest): the section's level is the middle
        // of 0 and 10 um, and the format error half the spike.
        let values: Vec<f64> = (0..20_001)
            .map(|k| if k == 12_107 { 10.0 } else { 0.0 })
            .collect();
        let leg = LegCorrection {
            leg: 0,
            lead_ppm: 0.0,
            table: Some(LegTableDescription::new(1, 640.0, 0.02, values)),
            reference_mm: 800.37,
            lo_mm: 640.0,
            hi_mm: 1040.0,
        };
        let spike_mm = 640.0 + 0.02 * 12_107.0;
        let a = plan(&leg, 100, 0, 0.1, 127);
        assert_eq!(a.interval_units, 40_817);
        let sample = (spike_mm - 800.37) / (a.interval_mm / 16.0);
        assert!((sample - sample.round()).abs() > 0.4, "{sample}");
        assert!(
            (a.format_error_um - 5.0).abs() < 0.06,
            "{}",
            a.format_error_um
        );
        // The section holding the spike reads -5 um (the output is added to
        // the command; the leg is 10 um long at the spike).
        assert!((a.output_mm(spike_mm, 0.1) + 0.005).abs() < 0.06e-3);
    }

    #[test]
    fn the_miss_just_above_a_section_s_lower_end_is_counted() {
        // A table rising from the stroke's start, 640 mm, to the upper end
        // of the second section (sections of 4.082 mm, whole um, from the
        // reference 660.37 mm), flat above: the largest miss lies in that section,
        // fully inside the rise. Its level is rounded to whole units, so
        // the miss is larger at one of its ends; a rise is chosen for which
        // that is the lower end, which belongs to the section below (only
        // approached from above, never a knot nor the stroke's end).
        let h = 4.082;
        let upper = 660.37 - 3.0 * h;
        let (lower_above, upper_at) = (upper - h + 1e-9, upper);
        let mut found = false;
        for rise_um in (20..60).map(f64::from) {
            let mut values = vec![rise_um; 51];
            values[0] = 0.0;
            let leg = LegCorrection {
                leg: 0,
                lead_ppm: 0.0,
                table: Some(LegTableDescription::new(1, 640.0, upper - 640.0, values)),
                reference_mm: 660.37,
                lo_mm: 640.0,
                hi_mm: 1040.0,
            };
            let a = plan(&leg, 100, 0, 1.0, 127);
            assert!((a.interval_mm - h).abs() < 1e-12, "{}", a.interval_mm);
            let miss = |q: f64| a.deviation_mm(&leg, q, 1.0).abs() * 1e3;
            let largest = largest_miss_um(&a, &leg, 1.0);
            if miss(lower_above) < largest - 1e-6 || miss(lower_above) < miss(upper_at) + 0.05 {
                continue;
            }
            found = true;
            assert!(
                (a.format_error_um - largest).abs() < 2e-3,
                "{rise_um} um: {} um reported, {largest} um found",
                a.format_error_um
            );
        }
        assert!(found);
    }

    #[test]
    fn a_hand_built_axis_outputs_its_values_summed_from_the_reference_outwards() {
        // Points 10 to 15, the reference 12 at 100 mm, 1 mm apart, in
        // units of 2 x 1 um. The module docs' reading: point n carries the
        // increment over the section from P_(n-1) to P_n; the reference's
        // own section (99, 100] outputs zero. Worked by hand:
        // section (100, 101]: +4; (101, 102]: 4 + 1; (102, 103]: 5 + 2;
        // (98, 99]: 0 - (-5) (the reference point's own value);
        // (97, 98]: 5 - 3; the first point's value (7) lies below the
        // table and never counts; beyond either end the end's level.
        let a = FanucAxis {
            reference_point: 12,
            first_point: 10,
            last_point: 15,
            magnification: 2,
            interval_units: 1000,
            interval_mm: 1.0,
            reference_mm: 100.0,
            increments: vec![7, 3, -5, 4, 1, 2],
            clipped: false,
            shift_mm: 0.0,
            format_error_um: 0.0,
        };
        let units = [(90.0, 2), (97.5, 2), (98.5, 5), (99.5, 0), (100.5, 4)]
            .into_iter()
            .chain([(101.5, 5), (102.5, 7), (110.0, 7)]);
        for (q_mm, level) in units {
            let expected_mm = f64::from(level) * 2.0 * 1e-3;
            assert!(
                (a.output_mm(q_mm, 1.0) - expected_mm).abs() < 1e-12,
                "{q_mm} mm: {} mm, not {expected_mm}",
                a.output_mm(q_mm, 1.0)
            );
        }
        // A section's upper end belongs to it, its lower end to the one
        // below.
        assert!((a.output_mm(101.0, 1.0) - 0.008).abs() < 1e-12);
        assert!((a.output_mm(98.0, 1.0) - 0.004).abs() < 1e-12);
    }

    #[test]
    fn the_largest_point_count_is_planned_with_its_format_error() {
        // --max-points' largest value (100000) over a 400 mm stroke in
        // 1 um units: the interval is the stroke over the 99998 sections
        // it may have, rounded up to whole units (4.00008 um -> 5 um). A
        // 50 ppm lead moves 0.25 nm over a section: the staircase misses
        // by half a unit, 0.5 um, plus at most that.
        let leg = lead(50.0);
        let a = plan(&leg, 100_000, 0, 1.0, 127);
        assert_eq!(a.interval_units, 5);
        assert_eq!(a.last_point - a.first_point + 1, 80_001);
        assert!(
            (0.5..0.51).contains(&a.format_error_um),
            "{}",
            a.format_error_um
        );
    }
}
