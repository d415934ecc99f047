//! How the effects of the vocabulary ([`tricept_model::effects`]) are put
//! into a simulated machine: each [`Effect`] carries its magnitude, and the
//! plant applies its physics to the legs, the readings, the machine's
//! kinematics or the logged rows.
//!
//! | name | magnitude |
//! |---|---|
//! | `leg-lead` | `ppm` per leg |
//! | `backlash` | `um` per leg |
//! | `thermal` | `drift_k` over the campaign, `expansion_ppm_per_k` |
//! | `scale-gain` | `ppm` |
//! | `encoder-eccentricity` | amplitude (arcsec) and phase (deg) per encoder |
//! | `ujoint-axes` | `skew_arcsec`, `offset_um` |
//! | `tube-twist` | `arcsec_per_100mm` |
//! | `compliance` | `stiffness_n_per_um_at_1m` |
//! | `outliers` | `count`, `size_sigma` |

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};
use tricept_data::MeasuredPose;
use tricept_kinematics::{Machine, UpJoints};
use tricept_model::effects::{
    EffectName, add_tube_twist, add_ujoint_axis_errors, backlash_extra_mm, compliance_extra_mm,
    eccentricity_error_rad, gravity_leg_tension_n, leg_lead_extra_mm, scale_gain_error_mm,
    thermal_extra_mm,
};

/// One unmodelled effect with its magnitude.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "effect", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Effect {
    /// Extra leg length `ppm_i 1e-6 q_i`.
    LegLead {
        /// Lead error of each leg, ppm.
        ppm: [f64; 3],
    },
    /// Lost motion `um_i` per leg.
    Backlash {
        /// Backlash of each leg, um.
        um: [f64; 3],
    },
    /// A linear temperature drift over the campaign and the legs' growth.
    Thermal {
        /// Temperature change from the first to the last pose, K.
        drift_k: f64,
        /// Effective expansion coefficient of the legs, ppm/K (steel: 11.5).
        expansion_ppm_per_k: f64,
    },
    /// Gain error of the linear scale.
    ScaleGain {
        /// Gain error, ppm.
        ppm: f64,
    },
    /// Once-per-revolution encoder errors.
    EncoderEccentricity {
        /// Amplitude on the phi encoder, arcsec.
        phi_arcsec: f64,
        /// Phase on the phi encoder, deg.
        phi_phase_deg: f64,
        /// Amplitude on the theta encoder, arcsec.
        theta_arcsec: f64,
        /// Phase on the theta encoder, deg.
        theta_phase_deg: f64,
    },
    /// U-joint axes not orthogonal and not intersecting.
    UjointAxes {
        /// Non-orthogonality, arcsec.
        skew_arcsec: f64,
        /// Distance between the axes, um.
        offset_um: f64,
    },
    /// Platform twist about the limb axis, proportional to extension from
    /// the workspace's middle plane.
    TubeTwist {
        /// Twist per 100 mm of extension, arcsec.
        arcsec_per_100mm: f64,
    },
    /// Axial leg deflection under gravity.
    Compliance {
        /// Axial stiffness of a leg of 1 m, N/um (scales as 1/length).
        stiffness_n_per_um_at_1m: f64,
    },
    /// Gross reading errors in a few rows.
    Outliers {
        /// Number of corrupted rows.
        count: usize,
        /// Size of each error in noise standard deviations (random sign).
        size_sigma: f64,
    },
}

/// What the effects may depend on at one pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseState {
    /// Commanded leg lengths, mm.
    pub commands_mm: [f64; 3],
    /// Nominal UP joints at the commands.
    pub nominal_up: UpJoints,
    /// Structure temperature minus the temperature at the first pose, K.
    pub delta_temp_k: f64,
    /// Sign of each leg's last motion.
    pub approach: [i8; 3],
}

impl Effect {
    /// The report name of this effect.
    pub fn name(&self) -> EffectName {
        match self {
            Effect::LegLead { .. } => EffectName::LegLead,
            Effect::Backlash { .. } => EffectName::Backlash,
            Effect::Thermal { .. } => EffectName::Thermal,
            Effect::ScaleGain { .. } => EffectName::ScaleGain,
            Effect::EncoderEccentricity { .. } => EffectName::EncoderEccentricity,
            Effect::UjointAxes { .. } => EffectName::UjointAxes,
            Effect::TubeTwist { .. } => EffectName::TubeTwist,
            Effect::Compliance { .. } => EffectName::Compliance,
            Effect::Outliers { .. } => EffectName::Outliers,
        }
    }

    /// Effects that change the machine's kinematics (class-2 errors).
    pub(crate) fn modify_machine(&self, m: &mut Machine) {
        match self {
            Effect::UjointAxes {
                skew_arcsec,
                offset_um,
            } => add_ujoint_axis_errors(m, *skew_arcsec, *offset_um),
            Effect::TubeTwist { arcsec_per_100mm } => add_tube_twist(m, *arcsec_per_100mm),
            _ => {}
        }
    }

    /// Temperature change (K) at `fraction` (0..1) of the campaign.
    pub(crate) fn temperature_drift_k(&self, fraction: f64) -> f64 {
        match self {
            Effect::Thermal { drift_k, .. } => drift_k * fraction,
            _ => 0.0,
        }
    }

    /// Adds this effect's extra length to the legs (mm).
    pub(crate) fn extra_leg_length(&self, nominal: &Machine, s: &PoseState, legs: &mut [f64; 3]) {
        match self {
            Effect::LegLead { ppm } => {
                for i in 0..3 {
                    legs[i] += leg_lead_extra_mm(ppm[i], s.commands_mm[i]);
                }
            }
            Effect::Backlash { um } => {
                for i in 0..3 {
                    legs[i] += backlash_extra_mm(um[i], s.approach[i]);
                }
            }
            Effect::Thermal {
                expansion_ppm_per_k,
                ..
            } => {
                for i in 0..3 {
                    legs[i] +=
                        thermal_extra_mm(*expansion_ppm_per_k, s.commands_mm[i], s.delta_temp_k);
                }
            }
            Effect::Compliance {
                stiffness_n_per_um_at_1m,
            } => {
                let f = gravity_leg_tension_n(nominal, &s.nominal_up);
                for i in 0..3 {
                    legs[i] +=
                        compliance_extra_mm(*stiffness_n_per_um_at_1m, f[i], s.commands_mm[i]);
                }
            }
            _ => {}
        }
    }

    /// Adds this effect's reading errors to clean readings `r` (rad, rad, mm)
    /// taken with the UP limb truly at `up`.
    pub(crate) fn reading_error(&self, up: &UpJoints, r: &mut [f64; 3]) {
        match self {
            Effect::ScaleGain { ppm } => r[2] += scale_gain_error_mm(*ppm, up.q4_mm),
            Effect::EncoderEccentricity {
                phi_arcsec,
                phi_phase_deg,
                theta_arcsec,
                theta_phase_deg,
            } => {
                r[0] += eccentricity_error_rad(*phi_arcsec, *phi_phase_deg, up.phi_rad);
                r[1] += eccentricity_error_rad(*theta_arcsec, *theta_phase_deg, up.theta_rad);
            }
            _ => {}
        }
    }

    /// Corrupts logged rows after noise (outliers). `sigma` is the logged
    /// noise per channel.
    pub(crate) fn corrupt_readings(&self, poses: &mut [MeasuredPose], seed: u64, sigma: &[f64; 3]) {
        if let Effect::Outliers { count, size_sigma } = self {
            let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x0071_1e25);
            let n = poses.len();
            let mut rows: Vec<usize> = Vec::new();
            while rows.len() < (*count).min(n) {
                let j = rng.random_range(0..n);
                if !rows.contains(&j) {
                    rows.push(j);
                }
            }
            for j in rows {
                let channel = rng.random_range(0..3);
                let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
                let mut r = poses[j].readings.to_array();
                r[channel] += sign * size_sigma * sigma[channel];
                poses[j].readings = tricept_data::Readings::from_array(r);
            }
        }
    }
}
