//! Leg effects a test adds to the true leg lengths, written from the
//! documented conventions (`docs/diagnosis.md`, `docs/data-format.md`),
//! never through the project's effect code: backlash by the sign of the
//! `dir1..dir3` column (`dir` is +1 when the leg last extended; the leg
//! stops `b/2` short in the direction it came from), a leg lead, a
//! quadratic leg, a ball-screw pitch error, a worn segment, and legs that
//! grow with temperature, each at its own temperature when they heat
//! unevenly. With [`TrueMachine::position`] a test commands the true
//! machine and sees where its platform goes.

use nalgebra::Vector3;

use crate::TrueMachine;

/// A leg effect: an extra true length of each leg, mm, as a function of
/// its command and the context of the pose ([`LegContext`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LegEffect {
    /// Lost motion at reversal, um per leg: the true length is
    /// `-dir_i b_i / 2` off.
    Backlash {
        /// `b_i`, um.
        um: [f64; 3],
    },
    /// A lead error: `k_i q_i`.
    Lead {
        /// `k_i`, ppm.
        ppm: [f64; 3],
    },
    /// A curved screw: `c_i ((q_i - centre) / half_width)^2`.
    Quadratic {
        /// `c_i`, um.
        um: [f64; 3],
        /// The centre of the curve, mm.
        centre_mm: f64,
        /// Its half width, mm.
        half_width_mm: f64,
    },
    /// A ball-screw pitch error: `a_i sin(2 pi q_i / P + phase_i)`.
    Pitch {
        /// `a_i`, um.
        um: [f64; 3],
        /// `P`, mm.
        period_mm: f64,
        /// `phase_i`, deg.
        phase_deg: [f64; 3],
    },
    /// A worn segment: `h_i` while `from <= q_i <= to`.
    Step {
        /// `h_i`, um.
        um: [f64; 3],
        /// Where it starts, mm.
        from_mm: f64,
        /// Where it ends, mm.
        to_mm: f64,
    },
    /// Legs that grow with their own temperature, `alpha (q_i + dq_i)
    /// (T + kelvin_i - 20)`: `T` the logged structure temperature, leg `i`
    /// `kelvin_i` warmer than it (all zero: the documented uniform
    /// `thermal`, legs at the logged temperature).
    Heating {
        /// `alpha`, ppm/K.
        ppm_per_k: f64,
        /// Each leg's temperature above the logged one, K.
        kelvin: [f64; 3],
    },
    /// Legs warming through the campaign with no temperature logged: leg
    /// `i` `kelvin_i` warmer at its end, linearly in the campaign's share
    /// `t` ([`LegContext::campaign_share`]), growing `alpha q_i kelvin_i t`
    /// (all `kelvin_i` equal: even heating).
    Drift {
        /// `alpha`, ppm/K.
        ppm_per_k: f64,
        /// Each leg's warming at the campaign's end, K.
        kelvin: [f64; 3],
    },
    /// Leg `leg` slips by `um` at the campaign's share `at` (0..1), for
    /// good: the delivered machine has slipped ([`LegEffect::delivered_mm`]).
    Slip {
        /// The leg (0-based).
        leg: usize,
        /// The slip, um.
        um: f64,
        /// When, as a share of the campaign.
        at: f64,
    },
    /// Legs warming unevenly as the structure warms: leg `i` at
    /// `T + kelvin_i (T - from) / (to - from)` (its own temperature
    /// response: `kelvin_i` more than the logged rise from `from` to `to`),
    /// growing `alpha (q_i + dq_i) (T_i - 20)`.
    Warming {
        /// `alpha`, ppm/K.
        ppm_per_k: f64,
        /// Each leg's extra warming over the logged rise, K.
        kelvin: [f64; 3],
        /// The logged temperature where the rise starts, deg C.
        from_c: f64,
        /// Where it ends, deg C.
        to_c: f64,
    },
}

/// What a leg effect may depend on besides the command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegContext {
    /// The logged structure temperature, deg C.
    pub temp_c: f64,
    /// The sign of each leg's last motion (+1: it extended).
    pub directions: [i8; 3],
    /// How far through the campaign the pose is: 0 at its first pose, 1
    /// at its last.
    pub campaign_share: f64,
}

/// The campaign share of the machine a file is delivered to: the thermal
/// state of the campaign's middle ([`LegEffect::Drift`]).
pub const DELIVERY_T: f64 = 0.5;

impl LegContext {
    /// A pose `campaign_share` through a campaign at 20 deg C, every leg
    /// last extended.
    pub fn at_share(campaign_share: f64) -> LegContext {
        LegContext {
            temp_c: 20.0,
            directions: [1; 3],
            campaign_share,
        }
    }
}

impl LegEffect {
    /// Extra true length of each leg at commands `q` (mm) on a machine
    /// whose leg offsets are `offsets_mm`, mm.
    pub fn extra_mm(&self, q: &[f64; 3], offsets_mm: &[f64; 3], at: &LegContext) -> [f64; 3] {
        std::array::from_fn(|i| match *self {
            LegEffect::Backlash { um } => -f64::from(at.directions[i]) * um[i] * 1e-3 / 2.0,
            LegEffect::Lead { ppm } => ppm[i] * 1e-6 * q[i],
            LegEffect::Quadratic {
                um,
                centre_mm,
                half_width_mm,
            } => um[i] * 1e-3 * ((q[i] - centre_mm) / half_width_mm).powi(2),
            LegEffect::Pitch {
                um,
                period_mm,
                phase_deg,
            } => {
                um[i]
                    * 1e-3
                    * (std::f64::consts::TAU * q[i] / period_mm + phase_deg[i].to_radians()).sin()
            }
            LegEffect::Step { um, from_mm, to_mm } => {
                if (from_mm..=to_mm).contains(&q[i]) {
                    um[i] * 1e-3
                } else {
                    0.0
                }
            }
            LegEffect::Drift { ppm_per_k, kelvin } => {
                ppm_per_k * 1e-6 * q[i] * kelvin[i] * at.campaign_share
            }
            LegEffect::Slip { leg, um, at: when } => {
                if i == leg % 3 && at.campaign_share >= when {
                    um * 1e-3
                } else {
                    0.0
                }
            }
            LegEffect::Heating { ppm_per_k, kelvin } => {
                ppm_per_k * 1e-6 * (q[i] + offsets_mm[i]) * (at.temp_c + kelvin[i] - 20.0)
            }
            LegEffect::Warming {
                ppm_per_k,
                kelvin,
                from_c,
                to_c,
            } => {
                let leg_c = at.temp_c + kelvin[i] * (at.temp_c - from_c) / (to_c - from_c);
                ppm_per_k * 1e-6 * (q[i] + offsets_mm[i]) * (leg_c - 20.0)
            }
        })
    }
}

impl LegEffect {
    /// The extra true length of each leg at commands `q` (mm) on the
    /// machine a file is delivered to ([`DELIVERY_T`] of the campaign at
    /// 20 deg C; a slip has slipped).
    pub fn delivered_mm(&self, q: &[f64; 3], offsets_mm: &[f64; 3]) -> [f64; 3] {
        let share = match self {
            LegEffect::Slip { .. } => f64::INFINITY,
            _ => DELIVERY_T,
        };
        self.extra_mm(q, offsets_mm, &LegContext::at_share(share))
    }
}

impl TrueMachine {
    /// True leg lengths at commands `q` (mm) on the machine a file is
    /// delivered to ([`LegEffect::delivered_mm`]).
    pub fn delivered_lengths(&self, q: &[f64; 3], effects: &[LegEffect]) -> [f64; 3] {
        self.summed(
            q,
            effects
                .iter()
                .map(|e| e.delivered_mm(q, &self.leg_offsets_mm)),
        )
    }

    /// True leg lengths at commands `q` (mm) with `effects` at `at`.
    pub fn lengths_with(&self, q: &[f64; 3], effects: &[LegEffect], at: &LegContext) -> [f64; 3] {
        self.summed(
            q,
            effects
                .iter()
                .map(|e| e.extra_mm(q, &self.leg_offsets_mm, at)),
        )
    }

    /// The true leg lengths at commands `q` (mm) plus every `extras` term.
    fn summed(&self, q: &[f64; 3], extras: impl Iterator<Item = [f64; 3]>) -> [f64; 3] {
        let mut l: [f64; 3] = std::array::from_fn(|i| q[i] + self.leg_offsets_mm[i]);
        for extra in extras {
            for i in 0..3 {
                l[i] += extra[i];
            }
        }
        l
    }

    /// The platform point `O' = q4 R e_z` of the UP limb's joints
    /// `[phi, theta, q4]` (`R = Rx(phi) Ry(theta)`), mm.
    pub fn position(&self, joints: &[f64; 3]) -> Vector3<f64> {
        let [phi, theta, q4] = *joints;
        let r = crate::rot(&Vector3::x(), phi) * crate::rot(&Vector3::y(), theta);
        r * Vector3::new(0.0, 0.0, q4)
    }

    /// Where the platform point goes at commands `q` with `effects` at
    /// `at`, mm.
    pub fn reach_with(&self, q: &[f64; 3], effects: &[LegEffect], at: &LegContext) -> Vector3<f64> {
        self.position(&self.forward_lengths(&self.lengths_with(q, effects, at)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slip_slips_at_its_share_and_stays_slipped_on_delivery() {
        let m = TrueMachine::random(0.0, 3);
        let q = [800.0, 820.0, 810.0];
        let slip = LegEffect::Slip {
            leg: 4,
            um: 20.0,
            at: 0.7,
        };
        let o = m.leg_offsets_mm;
        assert_eq!(slip.extra_mm(&q, &o, &LegContext::at_share(0.6)), [0.0; 3]);
        assert_eq!(
            slip.extra_mm(&q, &o, &LegContext::at_share(0.8)),
            [0.0, 0.02, 0.0]
        );
        assert_eq!(slip.delivered_mm(&q, &o), [0.0, 0.02, 0.0]);
        // Warmth is delivered at the campaign's middle.
        let drift = LegEffect::Drift {
            ppm_per_k: 10.0,
            kelvin: [1.0, 2.0, 0.0],
        };
        let d = drift.delivered_mm(&q, &o);
        assert!((d[1] - 10e-6 * 820.0 * 2.0 * DELIVERY_T).abs() < 1e-15);
    }

    #[test]
    fn backlash_shortens_the_leg_in_the_direction_it_came_from() {
        let m = TrueMachine::documented();
        let q = [800.0, 810.0, 820.0];
        let e = [LegEffect::Backlash {
            um: [10.0, 10.0, 10.0],
        }];
        let extended = LegContext {
            directions: [1, -1, 1],
            ..LegContext::at_share(0.0)
        };
        let l = m.lengths_with(&q, &e, &extended);
        assert!((l[0] - (800.0 - 0.005)).abs() < 1e-12);
        assert!((l[1] - (810.0 + 0.005)).abs() < 1e-12);
    }

    #[test]
    fn the_platform_point_closes_the_legs() {
        let m = TrueMachine::random(0.0, 3);
        let at = LegContext {
            temp_c: 22.0,
            ..LegContext::at_share(0.0)
        };
        let e = [LegEffect::Heating {
            ppm_per_k: 11.5,
            kelvin: [4.0, 1.0, -2.0],
        }];
        let q = [800.0, 790.0, 805.0];
        let x = m.reach_with(&q, &e, &at);
        // The documented machine: O' lies q4 along the limb from the U
        // joint at the base origin.
        let joints = m.forward_lengths(&m.lengths_with(&q, &e, &at));
        assert!((x.norm() - joints[2]).abs() < 1e-9);
        // Leg 1 is 6 K above 20 deg C: 11.5 ppm/K x 6 K of its length.
        let l = m.lengths_with(&q, &e, &at);
        let grown = 11.5e-6 * 6.0 * (800.0 + m.leg_offsets_mm[0]);
        assert!((l[0] - (800.0 + m.leg_offsets_mm[0]) - grown).abs() < 1e-12);
    }
}
