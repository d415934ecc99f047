//! Leg effects a test hides in a true machine, written from their physical
//! description alone (never through the simulator's effect code): each
//! adds to the true length of a leg, as a function of the leg's command
//! and of the time `t` (0 at the campaign's first pose, 1 at its last).
//!
//! - [`LegEffect::EvenHeating`]: every leg warms linearly through the
//!   campaign by the same kelvin, its length growing by `ppm_per_k`;
//! - [`LegEffect::UnevenHeating`]: the same, each leg by its own kelvin;
//! - [`LegEffect::Lead`]: a ball-screw lead error, `ppm` of the command;
//! - [`LegEffect::Quadratic`]: a curved screw, `peak_um` at the ends of
//!   the stroke and 0 in its middle;
//! - [`LegEffect::Slip`]: a leg that slips by `um` at time `at`, for good.
//!
//! The machine a file is then commanded on is the machine in the state
//! the campaign describes: at its mean temperature (`t = 0.5`) and after
//! any slip ([`DELIVERY_T`], [`TrueMachine::delivered_lengths`]; a slip is
//! permanent, warmth is not).

use nalgebra::Vector3;

use crate::{TrueMachine, rot};

/// The time of the delivered machine's thermal state: the campaign's mean.
pub const DELIVERY_T: f64 = 0.5;

/// One leg effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LegEffect {
    /// Every leg warms by `kelvin` over the campaign.
    EvenHeating {
        /// Warming at the campaign's end, K.
        kelvin: f64,
        /// Growth, ppm per K.
        ppm_per_k: f64,
    },
    /// Each leg warms by its own kelvin over the campaign.
    UnevenHeating {
        /// Warming of each leg at the campaign's end, K.
        kelvin: [f64; 3],
        /// Growth, ppm per K.
        ppm_per_k: f64,
    },
    /// A lead error of each leg, ppm of its command.
    Lead {
        /// ppm per leg.
        ppm: [f64; 3],
    },
    /// Leg `leg` is curved: `peak_um` at both ends of the stroke
    /// `[start_mm, end_mm]`, zero in its middle.
    Quadratic {
        /// The leg (0-based).
        leg: usize,
        /// The extra length at the stroke's ends, um.
        peak_um: f64,
        /// The stroke, mm.
        stroke_mm: [f64; 2],
    },
    /// Leg `leg` slips by `um` at time `at` (0..1), for good.
    Slip {
        /// The leg (0-based).
        leg: usize,
        /// The slip, um.
        um: f64,
        /// When, as a share of the campaign.
        at: f64,
    },
}

impl LegEffect {
    /// The extra true length of each leg, mm, at commands `q` (mm) and
    /// time `t`.
    pub fn extra_mm(&self, q: &[f64; 3], t: f64) -> [f64; 3] {
        let mut out = [0.0; 3];
        match *self {
            LegEffect::EvenHeating { kelvin, ppm_per_k } => {
                for (o, qi) in out.iter_mut().zip(q) {
                    *o = qi * ppm_per_k * 1e-6 * kelvin * t;
                }
            }
            LegEffect::UnevenHeating { kelvin, ppm_per_k } => {
                for i in 0..3 {
                    out[i] = q[i] * ppm_per_k * 1e-6 * kelvin[i] * t;
                }
            }
            LegEffect::Lead { ppm } => {
                for i in 0..3 {
                    out[i] = q[i] * ppm[i] * 1e-6;
                }
            }
            LegEffect::Quadratic {
                leg,
                peak_um,
                stroke_mm,
            } => {
                let mid = 0.5 * (stroke_mm[0] + stroke_mm[1]);
                let half = 0.5 * (stroke_mm[1] - stroke_mm[0]);
                out[leg % 3] = peak_um * 1e-3 * ((q[leg % 3] - mid) / half).powi(2);
            }
            LegEffect::Slip { leg, um, at } => {
                if t >= at {
                    out[leg % 3] = um * 1e-3;
                }
            }
        }
        out
    }
}

impl LegEffect {
    /// The extra true length of each leg, mm, at commands `q` on the
    /// machine a file is delivered to: at [`DELIVERY_T`], a slip slipped.
    pub fn delivered_mm(&self, q: &[f64; 3]) -> [f64; 3] {
        match *self {
            LegEffect::Slip { .. } => self.extra_mm(q, f64::INFINITY),
            _ => self.extra_mm(q, DELIVERY_T),
        }
    }
}

impl TrueMachine {
    /// True leg lengths at commands `q` on the machine a file is delivered
    /// to ([`LegEffect::delivered_mm`]).
    pub fn delivered_lengths(&self, q: &[f64; 3], effects: &[LegEffect]) -> [f64; 3] {
        self.lengths_plus(q, effects.iter().map(|e| e.delivered_mm(q)))
    }

    /// True leg lengths at commands `q` and time `t` with `effects` added.
    pub fn lengths_with(&self, q: &[f64; 3], effects: &[LegEffect], t: f64) -> [f64; 3] {
        self.lengths_plus(q, effects.iter().map(|e| e.extra_mm(q, t)))
    }

    fn lengths_plus(&self, q: &[f64; 3], extras: impl Iterator<Item = [f64; 3]>) -> [f64; 3] {
        let mut l: [f64; 3] = std::array::from_fn(|i| q[i] + self.leg_offsets_mm[i]);
        for x in extras {
            for i in 0..3 {
                l[i] += x[i];
            }
        }
        l
    }

    /// The platform point O' of joints `(phi, theta, q4)`: `R e_z q4`,
    /// `R = Rx(phi) Ry(theta)`.
    pub fn platform_point(joints: &[f64; 3]) -> Vector3<f64> {
        rot(&Vector3::x(), joints[0])
            * rot(&Vector3::y(), joints[1])
            * Vector3::new(0.0, 0.0, joints[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_platform_point_is_the_machines() {
        let m = TrueMachine::random(0.0, 3);
        let q = [800.0, 820.0, 810.0];
        let (r, _) = m.platform_pose(&q);
        let p = TrueMachine::platform_point(&m.forward_lengths(&m.lengths_with(&q, &[], 0.0)));
        assert!((r - p).norm() < 1e-9);
        let slip = LegEffect::Slip {
            leg: 4,
            um: 20.0,
            at: 0.5,
        };
        assert_eq!(slip.extra_mm(&q, 0.4), [0.0; 3]);
        assert_eq!(slip.extra_mm(&q, 0.6), [0.0, 0.02, 0.0]);
    }
}
