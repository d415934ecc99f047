//! Fanuc: pitch error compensation (parameters 3620-3624 per axis, the
//! values as pitch error compensation data `N10000+n P..`) and backlash
//! (parameter 1851), in detection units.
//!
//! How the control reads it (docs/controllers.md, with the sources): the
//! points are numbered, point `n` at `P_n = P_ref + (n - n_ref) h` with
//! `n_ref` (3620) the point of the reference position and `h` (3624) the
//! interval; "the compensation value is output at the compensation position
//! No. corresponding to each section between the coordinates": the value of
//! point `n` is the *increment* of the compensation over the section from
//! `P_(n-1)` to `P_n`, in detection units times the magnification (3623),
//! accumulated from the reference position outwards; the compensation is
//! output section by section (a staircase, no interpolation), zero at the
//! reference position, and added to the commanded position.
//!
//! Where in a section the step falls is not stated in the sources found:
//! on entering the section (the level of point `n` over `(P_(n-1), P_n]`,
//! [`StepAt::Entering`]) or on reaching the point (over `[P_n, P_(n+1))`,
//! [`StepAt::Reaching`]). Either reading is the other shifted by one
//! interval, so each level is planned for the two sections it may cover
//! (the middle of the correction's range over both), and the format error
//! is the worse of the two readings: the file is right whichever the
//! control does.

use crate::correction::LegCorrection;
use crate::setup::{ControlFiles, Deviation, Setup};

/// Samples per section when a level's range is sought.
const CHECKS_PER_SECTION: usize = 16;

/// Where in a section a control steps to the section's level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepAt {
    /// On entering the section: the level of point `n` holds over
    /// `(P_(n-1), P_n]`.
    Entering,
    /// On reaching the point: the level of point `n` holds over
    /// `[P_n, P_(n+1))`.
    Reaching,
}

impl StepAt {
    /// Both readings.
    pub const BOTH: [StepAt; 2] = [StepAt::Entering, StepAt::Reaching];
}

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
    /// position reads zero (added to the leg's zero), mm.
    pub shift_mm: f64,
    /// Largest difference between the compensation as output and the
    /// exact correction, over the stroke, in the worse of the two
    /// readings of [`StepAt`], um.
    pub format_error_um: f64,
}

impl FanucAxis {
    /// The compensation output at commanded position `q_mm` (mm, added to
    /// the command) when the control steps as `step_at` says: the
    /// staircase of the accumulated increments.
    pub fn output_mm(&self, q_mm: f64, detection_unit_um: f64, step_at: StepAt) -> f64 {
        self.staircase(detection_unit_um).output_mm(q_mm, step_at)
    }

    /// The positions of the first and the last point, mm: the span both
    /// readings of [`StepAt`] cover.
    pub fn span_mm(&self) -> (f64, f64) {
        let at = |n: usize| {
            self.reference_mm + (n as f64 - self.reference_point as f64) * self.interval_mm
        };
        (at(self.first_point), at(self.last_point))
    }

    /// The staircase the control outputs, each level's accumulated
    /// increments summed once: for the many check points at which a
    /// table's error is measured.
    pub(crate) fn staircase(&self, detection_unit_um: f64) -> Staircase {
        // The levels of the points from the first (3621) on.
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

/// An axis' output: each point's accumulated increments (in units of
/// `unit_mm`), from point `lo` (the first point's) on; beyond either end
/// the end's.
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
    pub(crate) fn output_mm(&self, q_mm: f64, step_at: StepAt) -> f64 {
        let u = (q_mm - self.reference_mm) / self.interval_mm;
        let k = match step_at {
            StepAt::Entering => section(q_mm, self.reference_mm, self.interval_mm),
            StepAt::Reaching => (u + 1e-12).floor() as i64,
        };
        let index = (k - self.lo).clamp(0, self.accumulated.len() as i64 - 1);
        self.accumulated.get(index as usize).copied().unwrap_or(0) as f64 * self.unit_mm
    }

    /// Where the control leaves the axis minus where the machine file asks
    /// for it, mm, at the exact command `q_mm`: the control adds its output
    /// to the setpoint the PKM transformation sends for it.
    pub(crate) fn deviation_mm(&self, leg: &LegCorrection, q_mm: f64, step_at: StepAt) -> f64 {
        let p = leg.setpoint_mm(q_mm, self.shift_mm);
        p + self.output_mm(p, step_at) - q_mm
    }

    /// The control's axis position minus the machine file's, mm, at
    /// setpoint `p_mm`: the output is added to the command.
    pub(crate) fn miss_at_setpoint_mm(
        &self,
        leg: &LegCorrection,
        p_mm: f64,
        step_at: StepAt,
    ) -> f64 {
        p_mm + self.output_mm(p_mm, step_at) - leg.exact_motor_mm(p_mm, self.shift_mm)
    }
}

/// The section (relative to the reference point's) that holds `q` when
/// the control steps on entering it: the section `k` runs from
/// `P_ref + (k - 1) h` (excluded) to `P_ref + k h`.
fn section(q_mm: f64, reference_mm: f64, interval_mm: f64) -> i64 {
    ((q_mm - reference_mm) / interval_mm - 1e-12).ceil() as i64
}

/// The value of point `j` (relative numbering, the first point at `lo`;
/// 0 beyond the points): the increment over the section up to it.
fn increment(increments: &[i64], lo: i64, j: i64) -> i64 {
    increments.get((j - lo) as usize).copied().unwrap_or(0)
}

/// The accumulated compensation of point `k` (relative numbering, the
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

/// The points (relative to the reference point's) an interval of `h`
/// needs so that the first lies at or below `lo_mm` and the last at or
/// above `hi_mm`.
fn points_for(lo_mm: f64, hi_mm: f64, reference_mm: f64, h: f64) -> (i64, i64) {
    let k_lo = ((lo_mm - reference_mm) / h + 1e-12).floor() as i64;
    let k_hi = ((hi_mm - reference_mm) / h - 1e-12).ceil() as i64;
    (k_lo, k_hi)
}

/// The smallest interval, in whole detection units of `du_mm`, whose
/// points cover the stroke of `leg` with at most `max_points` points.
fn interval_units(leg: &LegCorrection, max_points: usize, du_mm: f64) -> u64 {
    let count = |units: u64| {
        let (k_lo, k_hi) = points_for(leg.lo_mm, leg.hi_mm, leg.reference_mm, units as f64 * du_mm);
        (k_hi - k_lo + 1) as usize
    };
    let stroke = leg.hi_mm - leg.lo_mm;
    // At fewer units the points cannot cover the stroke; the count never
    // grows with the interval.
    let mut lo = ((stroke / (max_points.max(2) - 1) as f64) / du_mm)
        .floor()
        .max(1.0) as u64;
    let mut hi = lo.max(1);
    while count(hi) > max_points {
        lo = hi;
        hi = hi.saturating_mul(2);
    }
    if count(lo) <= max_points {
        return lo;
    }
    // count(lo) > max_points >= count(hi).
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if count(mid) <= max_points {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// `leg`'s correction as Fanuc pitch error compensation on at most
/// `max_points` points, numbered from `first_number`, in detection units
/// of `detection_unit_um` with increments of at most `max_increment` and
/// a magnification of at most `max_magnification`.
pub fn plan(
    leg: &LegCorrection,
    max_points: usize,
    first_number: usize,
    detection_unit_um: f64,
    max_increment: u32,
    max_magnification: u32,
) -> FanucAxis {
    let du_mm = detection_unit_um * 1e-3;
    // Three points at the least: the reference's and one each side.
    let max_points = max_points.max(3);
    let interval_units = interval_units(leg, max_points, du_mm);
    let h = interval_units as f64 * du_mm;
    let q_ref = leg.reference_mm;
    let (k_lo, k_hi) = points_for(leg.lo_mm, leg.hi_mm, q_ref, h);
    // Over the span of the points, which both readings cover (the summary
    // states it), not only the stroke.
    let leg = &LegCorrection {
        lo_mm: q_ref + k_lo as f64 * h,
        hi_mm: q_ref + k_hi as f64 * h,
        ..leg.clone()
    };
    // The middle of the correction's range over the two sections a level
    // may cover, setpoints (P_(k-1), P_(k+1)) within the span: the
    // control adds the level to the setpoint, and the file asks for the
    // axis at `x` with `x + E(x) - E(q_ref) - shift = p`.
    // The knots (kinks of the correction), once: a level takes those in
    // its sections (a setpoint grows with the command).
    let knots = leg.knots_mm();
    let midrange = |k: i64, shift: f64| {
        let a = (q_ref + (k - 1) as f64 * h).max(leg.lo_mm);
        let b = (q_ref + (k + 1) as f64 * h).min(leg.hi_mm);
        let checks = 2 * CHECKS_PER_SECTION;
        let first = knots.partition_point(|q| leg.setpoint_mm(*q, shift) < a);
        let inside = knots[first..]
            .iter()
            .map(|q| leg.setpoint_mm(*q, shift))
            .take_while(|p| *p <= b);
        let (lo, hi) = (0..=checks)
            .map(|j| a + (b - a) * j as f64 / checks as f64)
            .chain(inside)
            .map(|p| leg.relative_mm(leg.exact_motor_mm(p, shift)))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        0.5 * (lo + hi)
    };
    // The shift centres the reference's own level; the setpoints it maps
    // to depend on it a little: twice is enough.
    let shift_mm = midrange(0, midrange(0, 0.0));
    // The best staircase: each level at the middle of the correction's
    // range (negated: the compensation is added to the command).
    let target: Vec<f64> = (k_lo..=k_hi)
        .map(|k| {
            if k == 0 {
                0.0
            } else {
                -(midrange(k, shift_mm) - shift_mm)
            }
        })
        .collect();
    let mut chosen = (max_magnification.max(1), Vec::new(), true);
    for m in 1..=max_magnification.max(1) {
        let unit = f64::from(m) * du_mm;
        let (increments, clipped) = increments_of(&target, k_lo, unit, max_increment);
        if !clipped || m == max_magnification.max(1) {
            chosen = (m, increments, clipped);
            break;
        }
    }
    let (magnification, increments, clipped) = chosen;
    let mut axis = FanucAxis {
        reference_point: first_number + (-k_lo) as usize,
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
    // The staircase is constant between its points (setpoints) and the
    // exact correction at a setpoint linear between the setpoints of its
    // knots (a lead and a linearly interpolated table, solved for the axis
    // position): their difference is largest at a point or a knot's
    // setpoint, on one side or the other. The first and the last point are
    // the span's ends.
    let points = (k_lo..=k_hi).map(|k| q_ref + k as f64 * h);
    let kinks = knots.iter().map(|q| leg.setpoint_mm(*q, shift_mm));
    let staircase = axis.staircase(detection_unit_um);
    axis.format_error_um = points
        .chain(kinks)
        .flat_map(|p| [p - 1e-6, p, p + 1e-6])
        .filter(|p| (leg.lo_mm..=leg.hi_mm).contains(p))
        .flat_map(|p| StepAt::BOTH.map(|s| staircase.miss_at_setpoint_mm(leg, p, s).abs() * 1e3))
        .fold(0.0, f64::max);
    axis
}

/// The Fanuc files of `setup`: the pitch data and the parameter tape,
/// the parameters to set, and the limits past the tolerance or the
/// control's ranges (the range of a point, the point numbers).
pub(crate) fn files(setup: &Setup) -> ControlFiles {
    let options = setup.options;
    let model = options.control;
    let limits = model.limits();
    let du = options.detection_unit_um.unwrap_or(1.0);
    let range = limits.value_range.map_or(127, |l| l.value as u32);
    let cap = options.max_increment.unwrap_or(range);
    let max_magnification = limits.max_magnification.map_or(100, |l| l.value as u32);
    let mut next = 0;
    let axes: Vec<FanucAxis> = setup
        .legs
        .iter()
        .map(|l| {
            let a = plan(l, setup.max_points, next, du, cap, max_magnification);
            next = a.last_point + 1;
            a
        })
        .collect();
    let staircases: Vec<Staircase> = axes.iter().map(|a| a.staircase(du)).collect();
    let readings = StepAt::BOTH
        .map(|step_at| {
            std::array::from_fn(|i| {
                let (s, l) = (staircases[i].clone(), setup.legs[i].clone());
                Box::new(move |q| s.deviation_mm(&l, q, step_at)) as Deviation
            })
        })
        .into();
    let mut out = ControlFiles {
        files: Vec::new(),
        axes: Vec::new(),
        parameters: Vec::new(),
        limits: Vec::new(),
        carries_thermal: false,
        readings,
    };
    let names = &setup.names;
    for (i, a) in axes.iter().enumerate() {
        out.axes.push(setup.axis_summary(
            i,
            a.increments.len(),
            a.interval_mm,
            a.span_mm(),
            a.format_error_um,
            a.shift_mm,
        ));
        if a.clipped {
            out.limits.push(format!(
                "axis {}: a point's value exceeds {cap} (the range of a point on the {model}, or max_increment) even at magnification {max_magnification} (parameter 3623): raise max_points or detection_unit_um",
                names[i],
            ));
        } else if a.format_error_um > options.tolerance_um {
            out.limits
                .push(remedy(a, &names[i], du, options.tolerance_um));
        }
    }
    if let Some(numbers) = limits.point_numbers
        && next as u64 > numbers.value
    {
        out.limits.push(format!(
            "the three axes need compensation point numbers 0 to {}: the {model} has 0 to {} ({}): lower max_points to {}",
            next - 1,
            numbers.value - 1,
            numbers.source,
            numbers.value / 3
        ));
    }
    let backlash_units = setup.params.backlash_um.map(|b| (b / du).round() as i64);
    out.files.push(("PITCH.TXT".to_string(), pitch_tape(&axes)));
    out.files.push((
        "PARAM.TXT".to_string(),
        parameter_tape(&axes, &backlash_units),
    ));
    for (i, (a, ax)) in axes.iter().zip(names).enumerate() {
        out.parameters.push(format!(
            "{ax} (axis {}): 1851 = {} (backlash, detection units of {du} um); 3620 = {}; 3621 = {}; 3622 = {}; 3623 = {}; 3624 = {} ({:.4} mm)",
            i + 1,
            backlash_units[i],
            a.reference_point,
            a.first_point,
            a.last_point,
            a.magnification,
            a.interval_units,
            a.interval_mm
        ));
    }
    out
}

/// The remedy for axis `a` (named `name`) past the tolerance: a staircase
/// misses by about half a level's change plus half a unit, and the levels'
/// changes shrink with the points.
fn remedy(a: &FanucAxis, name: &str, du: f64, tolerance_um: f64) -> String {
    let rounding_um = 0.5 * du * f64::from(a.magnification);
    let lower = format!(
        "lower detection_unit_um ({du} um, magnification {}: half a unit is {rounding_um:.3} um)",
        a.magnification
    );
    let remedy = if rounding_um >= tolerance_um {
        lower
    } else {
        let points = a.increments.len() as f64 * (a.format_error_um - rounding_um)
            / (tolerance_um - rounding_um);
        format!(
            "raise max_points (the points of the axis) to more than {}, or {lower}",
            points.ceil()
        )
    };
    format!(
        "axis {name}: format error {:.3} um past tolerance_um {tolerance_um}: {remedy}",
        a.format_error_um
    )
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
mod tests;
