//! The vocabulary of effects that the paper's 15-parameter geometric model
//! leaves out, and their physics as pure functions: what a leg, a sensor or
//! the UP limb does under each effect, in the units a machine builder
//! quotes.
//!
//! | name | physics | quoted in |
//! |---|---|---|
//! | `leg-lead` | ball-screw lead error: extra length `k_i q_i` | ppm per leg |
//! | `backlash` | lost motion: the leg stops `b_i/2` short of the command in the direction it came from | um per leg |
//! | `thermal` | legs grow `alpha q_i dT` | ppm/K |
//! | `scale-gain` | the linear scale reads `(1 + g) q4` | ppm |
//! | `encoder-eccentricity` | once-per-revolution error `A sin(angle + psi)` of each encoder | arcsec |
//! | `ujoint-axes` | the UP limb's U-joint axes are not orthogonal (skew) and do not intersect (offset) | arcsec, um |
//! | `tube-twist` | twisted guide rails turn the platform about the limb axis as it extends | arcsec per 100 mm |
//! | `compliance` | the legs stretch under the weight of platform and head (`F = J1^-T Q`, stiffness ~ 1/length) | N/um at 1 m |
//! | `outliers` | a few gross reading errors | count |
//!
//! The same functions serve the plant simulator (which applies them to a
//! simulated machine) and the diagnosis (which fits them to measured data),
//! so that what is looked for is exactly what is simulated. Neither needs
//! the other: diagnosing real data does not depend on the simulator.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_kinematics::{Machine, UpJoints};

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
    /// Every effect, in the order of the vocabulary's table.
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

    /// Names of the parameters that describe the effect in a model, with
    /// their units (the diagnosis and the fused identification prefix them
    /// with the effect's name: `leg-lead.lead1_ppm`).
    ///
    /// # Example
    /// ```
    /// use tricept_model::effects::EffectName;
    /// assert_eq!(EffectName::ScaleGain.parameter_names(), ["scale_gain_ppm"]);
    /// assert!(EffectName::Outliers.parameter_names().is_empty());
    /// ```
    pub fn parameter_names(self) -> &'static [&'static str] {
        match self {
            EffectName::LegLead => &["lead1_ppm", "lead2_ppm", "lead3_ppm"],
            EffectName::Backlash => &["backlash1_um", "backlash2_um", "backlash3_um"],
            EffectName::Thermal => &["expansion_ppm_per_k"],
            EffectName::ScaleGain => &["scale_gain_ppm"],
            EffectName::EncoderEccentricity => &[
                "phi_sin_arcsec",
                "phi_cos_arcsec",
                "theta_sin_arcsec",
                "theta_cos_arcsec",
            ],
            EffectName::UjointAxes => &["axis_skew_arcsec", "axis_offset_um"],
            EffectName::TubeTwist => &["twist_arcsec_per_100mm"],
            EffectName::Compliance => &["compliance_um_per_kn_at_1m"],
            EffectName::Outliers => &[],
        }
    }

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
}

impl std::str::FromStr for EffectName {
    type Err = UnknownEffect;

    /// Parses a report name.
    ///
    /// # Example
    /// ```
    /// use tricept_model::effects::EffectName;
    /// assert_eq!("leg-lead".parse::<EffectName>(), Ok(EffectName::LegLead));
    /// assert!("pitch".parse::<EffectName>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<EffectName, UnknownEffect> {
        EffectName::ALL
            .into_iter()
            .find(|e| e.as_str() == s)
            .ok_or_else(|| UnknownEffect(s.to_string()))
    }
}

/// A name that is not in the vocabulary.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown effect `{0}` (known: leg-lead, backlash, thermal, scale-gain, encoder-eccentricity, ujoint-axes, tube-twist, compliance, outliers)"
)]
pub struct UnknownEffect(pub String);

impl std::fmt::Display for EffectName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
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
    amplitude_arcsec * RAD_PER_ARCSEC * (angle_rad + phase_deg.to_radians()).sin()
}

/// Adds U-joint axis errors to `machine`'s UP limb (class 2): the axes
/// skewed by `skew_arcsec` about their common normal and offset by
/// `offset_um` along it.
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// let mut m = Machine::paper();
/// tricept_model::effects::add_ujoint_axis_errors(&mut m, 30.0, 20.0);
/// assert!((m.up_limb.axis_offset_mm - 0.02).abs() < 1e-15);
/// ```
pub fn add_ujoint_axis_errors(machine: &mut Machine, skew_arcsec: f64, offset_um: f64) {
    machine.up_limb.axis_skew_rad += skew_arcsec * RAD_PER_ARCSEC;
    machine.up_limb.axis_offset_mm += offset_um * 1e-3;
}

/// Adds a twist of the UP limb's guide rails to `machine` (class 2): the
/// platform turns about the limb axis by `arcsec_per_100mm` per 100 mm of
/// extension from [`twist_reference_mm`].
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// let mut m = Machine::paper();
/// tricept_model::effects::add_tube_twist(&mut m, 30.0);
/// assert_eq!(m.up_limb.twist_reference_mm, 750.0);
/// ```
pub fn add_tube_twist(machine: &mut Machine, arcsec_per_100mm: f64) {
    machine.up_limb.twist_rad_per_mm += arcsec_per_100mm * RAD_PER_ARCSEC / 100.0;
    machine.up_limb.twist_reference_mm = twist_reference_mm(machine);
}

/// Extension at which the tube twist is zero: the UP limb length at the
/// workspace's middle plane on the axis.
pub fn twist_reference_mm(machine: &Machine) -> f64 {
    machine.workspace.mid_plane_z_mm()
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

/// Extra length (mm) per mm of command of each leg of `machine` from its
/// static leg effects ([`Machine::leg_effects`]) with the UP limb at `up`:
/// `lead_i 1e-6 + c F_i 1e-9`, the lead error plus the compliance `c`
/// (um/kN at 1 m) under the gravity tension `F_i` (N). Zero without effects.
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// let mut m = Machine::paper();
/// let up = m.forward(&[800.0; 3]).unwrap().up;
/// assert_eq!(tricept_model::effects::static_leg_extra_per_mm(&m, &up), [0.0; 3]);
/// m.leg_effects.lead_ppm = [50.0, 0.0, 0.0];
/// assert!((tricept_model::effects::static_leg_extra_per_mm(&m, &up)[0] - 5e-5).abs() < 1e-18);
/// ```
pub fn static_leg_extra_per_mm(machine: &Machine, up: &UpJoints) -> [f64; 3] {
    let e = &machine.leg_effects;
    let tension = if e.compliance_um_per_kn_at_1m != 0.0 {
        gravity_leg_tension_n(machine, up)
    } else {
        [0.0; 3]
    };
    std::array::from_fn(|i| {
        leg_lead_extra_mm(e.lead_ppm[i], 1.0)
            + e.compliance_um_per_kn_at_1m * compliance_extra_mm(1000.0, tension[i], 1.0)
    })
}
