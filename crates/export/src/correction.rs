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

use crate::ExportError;

/// Margin added to each end of the stroke the workspace uses, mm.
pub const STROKE_MARGIN_MM: f64 = 2.0;

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
    /// `start + k step`, and both sides of every knot.
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
    // The workspace cylinder's surface and axis: the leg commands are
    // extreme on its boundary.
    let levels = 9;
    let angles = 72;
    for l in 0..=levels {
        let z = w.z_min_mm + (w.z_max_mm - w.z_min_mm) * l as f64 / levels as f64;
        for ring in [0.0, 0.5, 1.0] {
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
            return Err(ExportError::Options(format!(
                "--reference-mm: leg {}'s reference point {} mm is outside the stroke the workspace uses ({} to {} mm)",
                l.leg + 1,
                l.reference_mm,
                l.lo_mm,
                l.hi_mm
            )));
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
