//! The exact per-leg correction a control's axis compensation must carry:
//! everything of the calibrated machine that depends on one leg's command
//! alone (ball-screw lead and the deployed compensation table), taken
//! relative to the axis' reference point, and the stroke the workspace
//! uses.
//!
//! The calibrated machine says that leg `i` commanded to `q` is
//! `E_i(q) = lead_i 1e-6 q + T_i(q)` (mm) longer than its geometry
//! (`LegEffectsDescription`). A control's leadscrew or pitch-error
//! compensation is zero at the reference point; the constant `E_i(q_ref)`
//! goes into the leg's zero instead (`AxisSummary::zero_mm`).

use nalgebra::Vector3;
use tricept_kinematics::Machine;
use tricept_kinematics::description::LegTableDescription;
use tricept_model::ExtendedMachine;

use crate::types::ExportError;

/// Margin added to each end of the stroke the workspace uses, mm.
pub const STROKE_MARGIN_MM: f64 = 2.0;

/// Rings of the workspace's end discs on which the stroke is sought.
const DISC_RINGS: usize = 32;

/// One leg's exact correction.
#[derive(Debug, Clone)]
pub struct LegCorrection {
    /// Leg index, 0 to 2.
    pub leg: usize,
    /// Ball-screw lead error, ppm of the command.
    pub lead_ppm: f64,
    /// The leg's deployed compensation table, when it has one.
    pub table: Option<LegTableDescription>,
    /// The axis position of the reference point, mm.
    pub reference_mm: f64,
    /// Lowest leg command the workspace needs (with margin), mm.
    pub lo_mm: f64,
    /// Highest leg command the workspace needs (with margin), mm.
    pub hi_mm: f64,
}

impl LegCorrection {
    /// `E(q)`: the extra length (mm) at command `q_mm`.
    pub fn extra_mm(&self, q_mm: f64) -> f64 {
        let table = self.table.as_ref().map_or(0.0, |t| t.extra_mm(q_mm));
        self.lead_ppm * 1e-6 * q_mm + table
    }

    /// `E(q) - E(q_ref)`: the extra length relative to the reference
    /// point, mm.
    pub fn relative_mm(&self, q_mm: f64) -> f64 {
        self.extra_mm(q_mm) - self.extra_mm(self.reference_mm)
    }

    /// The setpoint the PKM transformation sends for an exact leg command
    /// `q_mm` (the axis position the machine file asks for), mm: the leg
    /// length less the axis' zero, which holds the correction at the
    /// reference and the table's `shift_mm` (`q + E(q) - E(q_ref) -
    /// shift`).
    pub fn setpoint_mm(&self, q_mm: f64, shift_mm: f64) -> f64 {
        q_mm + self.relative_mm(q_mm) - shift_mm
    }

    /// The axis position the machine file asks for at setpoint `p_mm`:
    /// the inverse of [`LegCorrection::setpoint_mm`].
    pub fn exact_motor_mm(&self, p_mm: f64, shift_mm: f64) -> f64 {
        let constant = self.extra_mm(self.reference_mm) + shift_mm;
        settle(p_mm, |x| self.extra_mm(x) - constant)
    }

    /// Positions where the exact correction has a kink (the table's
    /// points inside the stroke), mm: a format error is largest there.
    pub fn knots_mm(&self) -> Vec<f64> {
        let Some(t) = &self.table else {
            return Vec::new();
        };
        (0..t.extra_length_um.len())
            .map(|k| t.start_mm + t.step_mm * k as f64)
            .filter(|q| (self.lo_mm..=self.hi_mm).contains(q))
            .collect()
    }

    /// Points at which a written table is compared with the exact
    /// correction: `per_cell` points in every cell of the grid
    /// `start + k step`, both sides of every knot, the stroke's ends.
    pub fn check_points_mm(&self, start_mm: f64, step_mm: f64, per_cell: usize) -> Vec<f64> {
        let mut out = Vec::new();
        let cells = ((self.hi_mm - start_mm) / step_mm).ceil().max(0.0) as usize;
        for c in 0..cells {
            for k in 0..=per_cell {
                let q = start_mm + step_mm * (c as f64 + k as f64 / per_cell as f64);
                if (self.lo_mm..=self.hi_mm).contains(&q) {
                    out.push(q);
                }
            }
        }
        for q in self.knots_mm() {
            out.extend([q - 1e-6, q, q + 1e-6]);
        }
        out.push(self.lo_mm);
        out.push(self.hi_mm);
        out
    }
}

/// Solves `x + error(x) = p` for `x` by fixed-point iteration: where an
/// axis settles whose position is corrected by `error` (a correction's
/// slope is far below 1: a table's is at most
/// `tricept_kinematics::description::MAX_TABLE_SLOPE_UM_PER_MM`).
pub fn settle(p_mm: f64, error: impl Fn(f64) -> f64) -> f64 {
    let mut x = p_mm;
    for _ in 0..100 {
        let next = p_mm - error(x);
        if (next - x).abs() <= 1e-10 || !next.is_finite() {
            return next;
        }
        x = next;
    }
    x
}

/// The three legs' corrections of `machine` (a calibrated machine with its
/// leg effects), over the stroke its workspace uses, each relative to its
/// reference point: `reference_mm`, or the leg's command at the centre of
/// the workspace.
pub fn leg_corrections(
    machine: &Machine,
    reference_mm: Option<[f64; 3]>,
) -> Result<[LegCorrection; 3], ExportError> {
    let extended = ExtendedMachine::new(machine.clone());
    let w = &machine.workspace;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    // The leg commands are extreme on the workspace cylinder's boundary
    // (a leg's length has no stationary point inside), its end discs
    // included: a leg is shortest on the lower disc about below its base
    // joint, at three quarters of the radius on the paper machine. So the
    // discs are sampled on rings 1/32 of the radius apart, the side on 10
    // levels (near its least the length grows with the square of the
    // distance from it, so a sample misses it by far less than the 2 mm
    // margin; the stroke test checks it against a finer sampling).
    let levels = 9;
    let angles = 72;
    let disc_rings: Vec<f64> = (0..=DISC_RINGS)
        .map(|k| k as f64 / DISC_RINGS as f64)
        .collect();
    for l in 0..=levels {
        let z = w.z_min_mm + (w.z_max_mm - w.z_min_mm) * l as f64 / levels as f64;
        let rings: &[f64] = if l == 0 || l == levels {
            &disc_rings
        } else {
            &[0.0, 1.0]
        };
        for &ring in rings {
            for a in 0..angles {
                let phi = std::f64::consts::TAU * a as f64 / angles as f64;
                let r = Vector3::new(
                    ring * w.radius_mm * phi.cos(),
                    ring * w.radius_mm * phi.sin(),
                    z,
                );
                let q = extended.inverse(&r)?.legs_mm;
                for i in 0..3 {
                    lo[i] = lo[i].min(q[i]);
                    hi[i] = hi[i].max(q[i]);
                }
            }
        }
    }
    let centre = Vector3::new(0.0, 0.0, 0.5 * (w.z_min_mm + w.z_max_mm));
    let reference = match reference_mm {
        Some(r) => r,
        None => extended.inverse(&centre)?.legs_mm,
    };
    let effects = &machine.leg_effects;
    Ok(std::array::from_fn(|i| {
        let lo_mm = (lo[i] - STROKE_MARGIN_MM).floor();
        let hi_mm = (hi[i] + STROKE_MARGIN_MM).ceil();
        LegCorrection {
            leg: i,
            lead_ppm: effects.lead_ppm[i],
            table: effects
                .tables
                .iter()
                .find(|t| t.leg_index() == Some(i))
                .cloned(),
            reference_mm: reference[i],
            lo_mm,
            hi_mm,
        }
    }))
}

/// Checks that every reference point lies inside the leg's stroke.
pub fn check_references(legs: &[LegCorrection; 3]) -> Result<(), ExportError> {
    for l in legs {
        if !(l.reference_mm.is_finite() && (l.lo_mm..=l.hi_mm).contains(&l.reference_mm)) {
            return Err(ExportError::Setting {
                setting: "reference_mm",
                why: format!(
                    "leg {}'s reference point {} mm is outside the stroke the workspace uses ({} to {} mm)",
                    l.leg + 1,
                    l.reference_mm,
                    l.lo_mm,
                    l.hi_mm
                ),
            });
        }
    }
    Ok(())
}

/// The largest change (um) of any leg command over `poses` that the
/// machine's gravity compliance makes: what a per-axis table cannot carry,
/// since it depends on the pose.
pub fn compliance_size_um(machine: &Machine, poses: &[Vector3<f64>]) -> Result<f64, ExportError> {
    if machine.leg_effects.compliance_um_per_kn_at_1m == 0.0 {
        return Ok(0.0);
    }
    let with = ExtendedMachine::new(machine.clone());
    let mut without = machine.clone();
    without.leg_effects.compliance_um_per_kn_at_1m = 0.0;
    let without = ExtendedMachine::new(without);
    let mut worst: f64 = 0.0;
    for r in poses {
        let a = with.inverse(r)?.legs_mm;
        let b = without.inverse(r)?.legs_mm;
        for i in 0..3 {
            worst = worst.max((a[i] - b[i]).abs());
        }
    }
    Ok(worst * 1e3)
}

/// The largest displacement (um) of the platform point over `poses` when
/// each leg `i` is `deviation[i](q_i)` mm longer than `machine`'s IK
/// commands it (the format errors of the written tables, read the way the
/// control reads them).
pub fn platform_error_um(
    machine: &Machine,
    poses: &[Vector3<f64>],
    deviation: &[Box<dyn Fn(f64) -> f64>],
) -> Result<f64, ExportError> {
    let extended = ExtendedMachine::new(machine.clone());
    let mut worst: f64 = 0.0;
    for r in poses {
        let q = extended.inverse(r)?.legs_mm;
        let g = machine.inverse(r)?.legs_mm;
        let moved: [f64; 3] =
            std::array::from_fn(|i| g[i] + deviation.get(i).map_or(0.0, |d| d(q[i])));
        let at = machine.forward(&g)?.position_mm;
        let to = machine.forward(&moved)?.position_mm;
        worst = worst.max((to - at).norm());
    }
    Ok(worst * 1e3)
}

/// A leg's length as the control leaves it at a command, minus the exact
/// one, mm.
pub type LegDeviation = Box<dyn Fn(f64) -> f64>;

/// The three legs' corrections over their strokes
/// ([`leg_corrections`]), each reference point checked inside its stroke
/// ([`check_references`]).
pub fn checked_leg_corrections(
    machine: &Machine,
    reference_mm: Option<[f64; 3]>,
) -> Result<[LegCorrection; 3], ExportError> {
    let legs = leg_corrections(machine, reference_mm)?;
    check_references(&legs)?;
    Ok(legs)
}

/// What a control's files leave of the machine's error, um: the largest
/// platform error over `poses` and over every reading the control may
/// make of the files (`readings`, each leg's deviation;
/// [`platform_error_um`]), and the gravity compliance no per-axis table
/// can carry ([`compliance_size_um`]).
pub fn left_by_files(
    machine: &Machine,
    poses: &[Vector3<f64>],
    readings: &[[LegDeviation; 3]],
) -> Result<(f64, f64), ExportError> {
    let mut platform_um: f64 = 0.0;
    for reading in readings {
        platform_um = platform_um.max(platform_error_um(machine, poses, reading)?);
    }
    Ok((platform_um, compliance_size_um(machine, poses)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leg(lo_mm: f64, hi_mm: f64, table: Option<LegTableDescription>) -> LegCorrection {
        LegCorrection {
            leg: 0,
            lead_ppm: 0.0,
            table,
            reference_mm: lo_mm,
            lo_mm,
            hi_mm,
        }
    }

    #[test]
    fn the_knots_are_the_table_points_inside_the_stroke() {
        // Points at 100, 102, ..., 118 mm; the stroke 103 to 111 mm.
        let t = LegTableDescription::new(1, 100.0, 2.0, vec![0.0; 10]);
        assert_eq!(
            leg(103.0, 111.0, Some(t)).knots_mm(),
            [104.0, 106.0, 108.0, 110.0]
        );
        assert!(leg(103.0, 111.0, None).knots_mm().is_empty());
    }

    #[test]
    fn the_check_points_fill_every_cell_and_flank_every_knot() {
        // The grid 100 + 4 k mm over the stroke 100 to 108 mm, 2 points a
        // cell: both ends of each of the 2 cells and its middle, then the
        // stroke's ends.
        assert_eq!(
            leg(100.0, 108.0, None).check_points_mm(100.0, 4.0, 2),
            [100.0, 102.0, 104.0, 104.0, 106.0, 108.0, 100.0, 108.0]
        );
        // A table's point at 104 mm inside the stroke 101 to 107 mm: the
        // grid's points inside the stroke, the knot and a um on each side.
        let t = LegTableDescription::new(1, 100.0, 4.0, vec![0.0; 3]);
        assert_eq!(
            leg(101.0, 107.0, Some(t)).check_points_mm(100.0, 4.0, 1),
            [
                104.0,
                104.0,
                104.0 - 1e-6,
                104.0,
                104.0 + 1e-6,
                101.0,
                107.0
            ]
        );
    }

    #[test]
    fn a_reference_point_outside_the_stroke_is_refused() {
        let mut legs = [0, 1, 2].map(|i| LegCorrection {
            leg: i,
            ..leg(100.0, 108.0, None)
        });
        assert!(check_references(&legs).is_ok());
        legs[2].reference_mm = 108.0;
        assert!(check_references(&legs).is_ok());
        for outside in [99.5, 108.5, f64::NAN] {
            legs[1].reference_mm = outside;
            let e = check_references(&legs).unwrap_err().to_string();
            assert!(
                e.contains(&format!("leg 2's reference point {outside} mm is outside"))
                    && e.contains("(100 to 108 mm)"),
                "{e}"
            );
        }
    }

    /// Each leg's least and largest command over `m`'s workspace cylinder,
    /// sampled inside and out every 1/40 of the radius and of the height,
    /// every degree.
    fn sampled_stroke(m: &Machine) -> ([f64; 3], [f64; 3]) {
        let w = &m.workspace;
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for l in 0..=40 {
            let z = w.z_min_mm + (w.z_max_mm - w.z_min_mm) * f64::from(l) / 40.0;
            for ring in (0..=40).map(|k| f64::from(k) / 40.0) {
                for a in 0..360 {
                    let phi = f64::from(a).to_radians();
                    let r = Vector3::new(
                        ring * w.radius_mm * phi.cos(),
                        ring * w.radius_mm * phi.sin(),
                        z,
                    );
                    let q = m.inverse(&r).unwrap().legs_mm;
                    for i in 0..3 {
                        lo[i] = lo[i].min(q[i]);
                        hi[i] = hi[i].max(q[i]);
                    }
                }
            }
        }
        (lo, hi)
    }

    #[test]
    fn the_stroke_holds_every_command_of_the_workspace_with_its_margin() {
        // The paper machine's leg commands over its workspace, and over
        // smaller and lower ones (other fractions of a mm at the ends), on
        // a finer grid than the export's: the stroke is each extreme
        // widened by the 2 mm margin and rounded outwards to a whole mm.
        // (Leg 1 is shortest at 0.75 of the radius on the lower disc: a
        // stroke sought on the side and the axis alone missed 1.4 mm of
        // it.)
        let paper = Machine::paper();
        let mut machines = vec![paper.clone()];
        for (radius, lower_mm) in [(0.9, 0.0), (0.8, 7.3), (0.7, 13.9)] {
            let mut m = paper.clone();
            m.workspace.radius_mm *= radius;
            m.workspace.z_min_mm += lower_mm;
            m.workspace.z_max_mm -= lower_mm;
            machines.push(m);
        }
        for m in &machines {
            let legs = leg_corrections(m, None).unwrap();
            let (lo, hi) = sampled_stroke(m);
            let w = &m.workspace;
            for (i, l) in legs.iter().enumerate() {
                assert_eq!(l.leg, i);
                assert_eq!(l.lo_mm, l.lo_mm.round());
                assert_eq!(l.hi_mm, l.hi_mm.round());
                assert!(
                    l.lo_mm <= lo[i] - STROKE_MARGIN_MM + 0.06
                        && l.lo_mm > lo[i] - STROKE_MARGIN_MM - 1.01,
                    "leg {i}: {} for {}",
                    l.lo_mm,
                    lo[i]
                );
                assert!(
                    l.hi_mm >= hi[i] + STROKE_MARGIN_MM - 0.06
                        && l.hi_mm < hi[i] + STROKE_MARGIN_MM + 1.01,
                    "leg {i}: {} for {}",
                    l.hi_mm,
                    hi[i]
                );
                // The reference point: the leg's command at the workspace's
                // centre.
                let centre = Vector3::new(0.0, 0.0, 0.5 * (w.z_min_mm + w.z_max_mm));
                assert!((l.reference_mm - m.inverse(&centre).unwrap().legs_mm[i]).abs() < 1e-9);
            }
        }
        let m = paper;
        let given = leg_corrections(&m, Some([700.0, 800.0, 900.0])).unwrap();
        assert_eq!(given.map(|l| l.reference_mm), [700.0, 800.0, 900.0]);
    }
}
