//! A ballbar and a touch probe, written from the documented conventions
//! (`docs/data-format.md`, "External measurements"; `docs/hybrid.md`): the
//! bar reads the distance from the ball in the spindle (at the tool tip
//! plus an offset) to a pivot on the table; the probe's stylus centre is
//! the tool tip, and it triggers where the stylus ball of radius `r`
//! touches a sphere of radius `R`, `|x - c| = R + r`, latching the leg
//! commands of that moment. Leg effects (`effects`) are in the true leg
//! lengths in the state of delivery ([`TrueMachine::delivered_lengths`]).

use nalgebra::{Matrix3, Vector3};
use rand_pcg::Pcg64Mcg;

use crate::{LegEffect, TrueMachine, normal};

/// The spindle point beyond the tool tip at commands `q` with `effects` in
/// the true leg lengths.
fn spindle(
    truth: &TrueMachine,
    q: &[f64; 3],
    h: [f64; 2],
    extension_mm: f64,
    offset_mm: &Vector3<f64>,
    effects: &[LegEffect],
) -> Vector3<f64> {
    let joints = truth.forward_lengths(&truth.delivered_lengths(q, effects));
    truth.spindle_point_at(&joints, h, extension_mm, offset_mm)
}

/// A ballbar on a pivot, read to 1 um.
#[derive(Debug, Clone, Copy)]
pub struct TrueBallbar {
    /// The pivot's centre, base frame, mm.
    pub pivot_mm: Vector3<f64>,
    /// Noise of one reading, um.
    pub sigma_um: f64,
}

impl TrueBallbar {
    /// The reading at commands `q` and head angles `h`, the ball at the
    /// tool tip plus `ball_mm` (spindle frame at zero head angles).
    pub fn read(
        &self,
        truth: &TrueMachine,
        q: &[f64; 3],
        h: [f64; 2],
        ball_mm: &Vector3<f64>,
        effects: &[LegEffect],
        rng: &mut Pcg64Mcg,
    ) -> f64 {
        let x = spindle(truth, q, h, 0.0, ball_mm, effects);
        (x - self.pivot_mm).norm() + 1e-3 * self.sigma_um * normal(rng)
    }
}

/// A reference sphere touched by a probe whose stylus centre is the tool
/// tip.
#[derive(Debug, Clone, Copy)]
pub struct TrueSphere {
    /// Its centre, base frame, mm.
    pub centre_mm: Vector3<f64>,
    /// Its radius, mm.
    pub radius_mm: f64,
    /// The stylus ball's effective radius (pre-travel included), mm.
    pub stylus_mm: f64,
    /// Scatter of a trigger along the surface normal, um.
    pub sigma_um: f64,
    /// The stylus centre's distance beyond the tool tip along the tool, mm
    /// (0: the probe's stylus centre is the tool tip, as documented; a
    /// probe longer than the tool the other instruments measured
    /// otherwise).
    pub beyond_tip_mm: f64,
}

impl TrueSphere {
    /// The commands latched when the probe, at head angles `h`, starts at
    /// commands `q0` and moves towards the sphere's centre: the controller
    /// moves the documented machine's tool tip along the line from where it
    /// believes the tip is to the sphere's centre (its own Jacobian, of
    /// [`TrueMachine::documented`]), and the true tip triggers at `|x - c|
    /// = R + r` plus the trigger's scatter. `None` when the approach does
    /// not close (the sphere out of reach from `q0`).
    pub fn touch(
        &self,
        truth: &TrueMachine,
        q0: &[f64; 3],
        h: [f64; 2],
        effects: &[LegEffect],
        rng: &mut Pcg64Mcg,
    ) -> Option<[f64; 3]> {
        let documented = TrueMachine::documented();
        let tip = |m: &TrueMachine, q: &[f64; 3]| m.spindle_point(q, h, 0.0, &Vector3::zeros());
        let stylus =
            |q: &[f64; 3]| spindle(truth, q, h, self.beyond_tip_mm, &Vector3::zeros(), effects);
        // The documented tip's Jacobian in the commands, central differences.
        let mut j = Matrix3::zeros();
        for c in 0..3 {
            let (mut up, mut down) = (*q0, *q0);
            up[c] += 1e-3;
            down[c] -= 1e-3;
            j.set_column(
                c,
                &((tip(&documented, &up) - tip(&documented, &down)) / 2e-3),
            );
        }
        let inward = (self.centre_mm - tip(&documented, q0)).try_normalize(1e-9)?;
        let dq = j.try_inverse()? * inward;
        let at = |t: f64| -> [f64; 3] { std::array::from_fn(|c| q0[c] + t * dq[c]) };
        let contact = self.radius_mm + self.stylus_mm + 1e-3 * self.sigma_um * normal(rng);
        let gap = |t: f64| (stylus(&at(t)) - self.centre_mm).norm() - contact;
        // Newton on the gap along the approach, secant derivative.
        let mut t = 0.0_f64;
        for _ in 0..50 {
            let g = gap(t);
            if g.abs() < 1e-10 {
                return Some(at(t));
            }
            let d = (gap(t + 1e-3) - gap(t - 1e-3)) / 2e-3;
            if d.abs() < 1e-6 || t.abs() > 50.0 {
                return None;
            }
            t -= g / d;
        }
        None
    }
}
