//! Effects that the paper's 15-parameter geometric model leaves out, each
//! with a physical model, a magnitude in the units a machine builder quotes,
//! and the name the diagnosis report uses ([`EffectName`]).
//!
//! | name | physics | parameters |
//! |---|---|---|
//! | `leg-lead` | ball-screw lead error: extra length `k_i q_i` | `k_i` ppm per leg |
//! | `backlash` | lost motion: the leg stops `b_i/2` short of the command in the direction it came from | `b_i` um per leg |
//! | `thermal` | the structure warms by `drift_k` over the campaign; legs grow `alpha q_i dT` | drift K, `alpha` ppm/K |
//! | `scale-gain` | the linear scale reads `(1 + g) q4` | `g` ppm |
//! | `encoder-eccentricity` | once-per-revolution error `A sin(angle + psi)` of each encoder | `A` arcsec, `psi` deg per encoder |
//! | `ujoint-axes` | the UP limb's U-joint axes are not orthogonal (skew) and do not intersect (offset) | arcsec, um |
//! | `tube-twist` | twisted guide rails turn the platform about the limb axis as it extends | arcsec per 100 mm |
//! | `compliance` | the legs stretch under the weight of platform and head (`F = J1^-T Q`, stiffness ~ 1/length) | N/um at 1 m |
//! | `outliers` | a few gross reading errors | count, size in sigmas |
//!
//! The functional forms are public so that the diagnosis can fit exactly
//! the same physics it is asked to find.

use nalgebra::{Matrix3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};
use tricept_data::MeasuredPose;
use tricept_kinematics::{Machine, SensorNoise, UpJoints};

/// The vocabulary of the diagnosis report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EffectName {
    /// Ball-screw lead error of the actuated legs.
    LegLead,
    /// Lost motion of the actuated legs.
    Backlash,
    /// Thermal growth of the legs during a temperature drift.
    Thermal,
    /// Gain error of the UP limb's linear scale.
    ScaleGain,
    /// Once-per-revolution error of the U-joint encoders.
    EncoderEccentricity,
    /// Class-2 errors of the UP limb's U joint.
    UjointAxes,
    /// Platform twist about the UP limb's axis.
    TubeTwist,
    /// Gravity-induced axial deflection of the legs.
    Compliance,
    /// Gross reading errors.
    Outliers,
}

impl EffectName {
    /// Every effect, in the order of the vocabulary.
    pub const ALL: [EffectName; 9] = [
        EffectName::LegLead,
        EffectName::Backlash,
        EffectName::Thermal,
        EffectName::ScaleGain,
        EffectName::EncoderEccentricity,
        EffectName::UjointAxes,
        EffectName::TubeTwist,
        EffectName::Compliance,
        EffectName::Outliers,
    ];

    /// The report name (`leg-lead`, ...).
    pub fn as_str(self) -> &'static str {
        match self {
            EffectName::LegLead => "leg-lead",
            EffectName::Backlash => "backlash",
            EffectName::Thermal => "thermal",
            EffectName::ScaleGain => "scale-gain",
            EffectName::EncoderEccentricity => "encoder-eccentricity",
            EffectName::UjointAxes => "ujoint-axes",
            EffectName::TubeTwist => "tube-twist",
            EffectName::Compliance => "compliance",
            EffectName::Outliers => "outliers",
        }
    }

    /// Parses a report name.
    pub fn parse(s: &str) -> Option<EffectName> {
        EffectName::ALL.into_iter().find(|e| e.as_str() == s)
    }
}

impl std::fmt::Display for EffectName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

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

/// Extra leg length of a ball-screw lead error, mm.
pub fn leg_lead_extra_mm(ppm: f64, command_mm: f64) -> f64 {
    ppm * 1e-6 * command_mm
}

/// Extra leg length from backlash `um` approached in direction `dir`, mm:
/// the nut lags, so an extending leg stops short and a retracting one long.
pub fn backlash_extra_mm(um: f64, dir: i8) -> f64 {
    -f64::from(dir) * 0.5 * um * 1e-3
}

/// Thermal growth of a leg of length `command_mm` warmed by `delta_k`, mm.
pub fn thermal_extra_mm(ppm_per_k: f64, command_mm: f64, delta_k: f64) -> f64 {
    ppm_per_k * 1e-6 * command_mm * delta_k
}

/// Standard gravity, m/s^2.
pub const GRAVITY_M_PER_S2: f64 = 9.80665;

/// Axial tension in each leg (N) holding platform and head against gravity
/// with the UP limb at `up`: `F = J1^-T Q`, where `Q` is the generalised
/// gravity force on `(phi, theta, q4)`. The UP limb's passive prismatic
/// joint carries no axial load, so the legs carry all of it.
pub fn gravity_leg_tension_n(machine: &Machine, up: &UpJoints) -> [f64; 3] {
    let g = machine.legs_at(up);
    let loads = &machine.loads;
    let d = Vector3::from(loads.gravity_direction).normalize() * GRAVITY_M_PER_S2;
    let limb = &g.limb;
    let head_com = limb.position_mm + limb.rotation * Vector3::from(loads.head_com_mm);
    let q = limb.point_jacobian(&limb.position_mm).transpose() * (loads.platform_mass_kg * d)
        + limb.point_jacobian(&head_com).transpose() * (loads.head_mass_kg * d);
    let j1t: Matrix3<f64> = g.j1().transpose();
    match j1t.try_inverse() {
        Some(inv) => (inv * q).into(),
        None => [0.0; 3],
    }
}

/// Extra leg length (mm) of a leg of length `command_mm` under `tension_n`
/// with stiffness `stiffness_n_per_um_at_1m` at 1 m.
pub fn compliance_extra_mm(stiffness_n_per_um_at_1m: f64, tension_n: f64, command_mm: f64) -> f64 {
    let stiffness = stiffness_n_per_um_at_1m * 1000.0 / command_mm;
    tension_n / stiffness * 1e-3
}

/// Reading error of a scale with gain error `ppm` at extension `q4_mm`, mm.
pub fn scale_gain_error_mm(ppm: f64, q4_mm: f64) -> f64 {
    ppm * 1e-6 * q4_mm
}

/// Once-per-revolution encoder error at `angle_rad`, rad.
pub fn eccentricity_error_rad(amplitude_arcsec: f64, phase_deg: f64, angle_rad: f64) -> f64 {
    amplitude_arcsec * SensorNoise::ARCSEC * (angle_rad + phase_deg.to_radians()).sin()
}

/// Extension at which the tube twist is zero: the UP limb length at the
/// workspace's middle plane on the axis.
pub fn twist_reference_mm(machine: &Machine) -> f64 {
    machine.workspace.mid_plane_z_mm()
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
            } => {
                m.up_limb.axis_skew_rad += skew_arcsec * SensorNoise::ARCSEC;
                m.up_limb.axis_offset_mm += offset_um * 1e-3;
            }
            Effect::TubeTwist { arcsec_per_100mm } => {
                m.up_limb.twist_rad_per_mm += arcsec_per_100mm * SensorNoise::ARCSEC / 100.0;
                m.up_limb.twist_reference_mm = twist_reference_mm(m);
            }
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

/// The leg stiffness (N/um at 1 m) for which gravity moves the platform
/// point by `deflection_um` at the centre of the workspace's middle plane
/// (the magnitude in which the `compliance` effect is quoted).
pub fn stiffness_for_platform_deflection(machine: &Machine, deflection_um: f64) -> f64 {
    let r = Vector3::new(0.0, 0.0, machine.workspace.mid_plane_z_mm());
    let Ok(ik) = machine.inverse(&r) else {
        return f64::NAN;
    };
    let f = gravity_leg_tension_n(machine, &ik.up);
    // Deflection at unit stiffness (1 N/um at 1 m), through the exact FK.
    let legs: [f64; 3] =
        std::array::from_fn(|i| ik.legs_mm[i] + compliance_extra_mm(1.0, f[i], ik.legs_mm[i]));
    match machine.forward_from(&legs, &ik.up) {
        Ok(fk) => (fk.position_mm - r).norm() * 1e3 / deflection_um,
        Err(_) => f64::NAN,
    }
}
