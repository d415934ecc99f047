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
//!
//! Beyond the vocabulary, the diagnosis searches a dictionary of *generic*
//! terms ([`GenericFamily`]: periodic and polynomial leg-length errors,
//! drifts with time or temperature, encoder gains, scale non-linearity,
//! sensor reversal errors) so that an effect outside the vocabulary is
//! described in physical words rather than mistaken for a known one. Their
//! functional forms ([`periodic_extra_mm`], [`legendre_p2`],
//! [`encoder_gain_error_rad`], [`linear_drift`], ...) are here too: the
//! simulator's out-of-vocabulary effects use them. A report names either
//! kind by a [`CauseName`].

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

/// Families of generic terms: physically readable forms that are not
/// effects of the vocabulary, searched when the vocabulary leaves a misfit.
///
/// | name | form | a machine builder reads it as |
/// |---|---|---|
/// | `leg-periodic` | `a_i sin(2 pi q_i / P) + b_i cos(2 pi q_i / P)` per leg | ball-screw pitch error (period = lead) |
/// | `leg-polynomial` | `c1_i x_i + c2_i P2(x_i) + c3_i P3(x_i)`, `x_i` the leg's stroke over the campaign on `[-1, 1]` | mean travel deviation and travel variation of a screw, a bent guide |
/// | `reading-drift` | reading drifts linearly with time (or pose order) | sensor or mounting drift |
/// | `reading-temperature` | reading changes with the logged temperature | thermal drift of the sensor path |
/// | `leg-drift` | leg lengths drift linearly with time | creep, drive warm-up |
/// | `encoder-gain` | encoder reads `(1 + g) angle` | encoder scaling or interpolation fault |
/// | `scale-polynomial` | `h2 P2(x_4) + h3 P3(x_4)` on the scale | scale bending or mounting |
/// | `reading-hysteresis` | reading offset by `h/2` in the direction the sensor moved | sensor reversal error |
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GenericFamily {
    /// Leg-length error periodic in the leg length.
    LegPeriodic,
    /// Leg-length error quadratic and cubic in the leg length.
    LegPolynomial,
    /// A reading drifting with time.
    ReadingDrift,
    /// A reading changing with temperature.
    ReadingTemperature,
    /// Leg lengths drifting with time.
    LegDrift,
    /// Gain error of an encoder.
    EncoderGain,
    /// Quadratic and cubic error of the linear scale.
    ScalePolynomial,
    /// Reversal error of a sensor.
    ReadingHysteresis,
}

impl GenericFamily {
    /// Every family, in the order of the table.
    pub const ALL: [GenericFamily; 8] = [
        GenericFamily::LegPeriodic,
        GenericFamily::LegPolynomial,
        GenericFamily::ReadingDrift,
        GenericFamily::ReadingTemperature,
        GenericFamily::LegDrift,
        GenericFamily::EncoderGain,
        GenericFamily::ScalePolynomial,
        GenericFamily::ReadingHysteresis,
    ];

    /// The report name (`leg-periodic`, ...).
    ///
    /// # Example
    /// ```
    /// use tricept_model::effects::GenericFamily;
    /// assert_eq!(GenericFamily::LegPeriodic.as_str(), "leg-periodic");
    /// assert_eq!("encoder-gain".parse(), Ok(GenericFamily::EncoderGain));
    /// ```
    pub fn as_str(self) -> &'static str {
        match self {
            GenericFamily::LegPeriodic => "leg-periodic",
            GenericFamily::LegPolynomial => "leg-polynomial",
            GenericFamily::ReadingDrift => "reading-drift",
            GenericFamily::ReadingTemperature => "reading-temperature",
            GenericFamily::LegDrift => "leg-drift",
            GenericFamily::EncoderGain => "encoder-gain",
            GenericFamily::ScalePolynomial => "scale-polynomial",
            GenericFamily::ReadingHysteresis => "reading-hysteresis",
        }
    }
}

impl std::str::FromStr for GenericFamily {
    type Err = UnknownEffect;

    fn from_str(s: &str) -> Result<GenericFamily, UnknownEffect> {
        GenericFamily::ALL
            .into_iter()
            .find(|e| e.as_str() == s)
            .ok_or_else(|| UnknownEffect(s.to_string()))
    }
}

impl std::fmt::Display for GenericFamily {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The name of a cause in a report: an effect of the vocabulary or a
/// generic family. Serialised as the bare kebab-case name.
///
/// # Example
/// ```
/// use tricept_model::effects::{CauseName, EffectName, GenericFamily};
/// let c = CauseName::Catalogue(EffectName::Thermal);
/// assert!(c == EffectName::Thermal);
/// assert_eq!(serde_json::to_value(CauseName::Generic(GenericFamily::LegPeriodic)).unwrap(), "leg-periodic");
/// assert_eq!("reading-drift".parse::<CauseName>().unwrap().to_string(), "reading-drift");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(untagged)]
pub enum CauseName {
    /// An effect of the vocabulary.
    Catalogue(EffectName),
    /// A generic family.
    Generic(GenericFamily),
}

impl CauseName {
    /// The report name.
    pub fn as_str(self) -> &'static str {
        match self {
            CauseName::Catalogue(e) => e.as_str(),
            CauseName::Generic(g) => g.as_str(),
        }
    }

    /// The effect of the vocabulary, if it is one.
    pub fn catalogue(self) -> Option<EffectName> {
        match self {
            CauseName::Catalogue(e) => Some(e),
            CauseName::Generic(_) => None,
        }
    }

    /// Whether this is a generic family.
    pub fn is_generic(self) -> bool {
        matches!(self, CauseName::Generic(_))
    }
}

impl PartialEq<EffectName> for CauseName {
    fn eq(&self, other: &EffectName) -> bool {
        *self == CauseName::Catalogue(*other)
    }
}

impl PartialEq<GenericFamily> for CauseName {
    fn eq(&self, other: &GenericFamily) -> bool {
        *self == CauseName::Generic(*other)
    }
}

impl From<EffectName> for CauseName {
    fn from(e: EffectName) -> CauseName {
        CauseName::Catalogue(e)
    }
}

impl From<GenericFamily> for CauseName {
    fn from(g: GenericFamily) -> CauseName {
        CauseName::Generic(g)
    }
}

impl std::str::FromStr for CauseName {
    type Err = UnknownEffect;

    fn from_str(s: &str) -> Result<CauseName, UnknownEffect> {
        s.parse::<EffectName>()
            .map(CauseName::Catalogue)
            .or_else(|_| s.parse::<GenericFamily>().map(CauseName::Generic))
    }
}

impl std::fmt::Display for CauseName {
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

/// Extra leg length (mm) of a periodic error of period `period_mm` in the
/// leg length `command_mm`, with sine and cosine amplitudes in um (a
/// ball-screw pitch error: `A sin(2 pi q / P + psi)` has sine amplitude
/// `A cos psi` and cosine amplitude `A sin psi`).
///
/// # Example
/// ```
/// use tricept_model::effects::periodic_extra_mm;
/// // 4 um sine amplitude, a quarter period in: the full 4 um.
/// assert!((periodic_extra_mm(4.0, 0.0, 10.0, 802.5) - 0.004).abs() < 1e-12);
/// ```
pub fn periodic_extra_mm(sin_um: f64, cos_um: f64, period_mm: f64, command_mm: f64) -> f64 {
    let (s, c) = (std::f64::consts::TAU * command_mm / period_mm).sin_cos();
    (sin_um * s + cos_um * c) * 1e-3
}

/// `x` in `[lo, hi]` mapped linearly onto `[-1, 1]` (`0` when the range is
/// empty).
///
/// # Example
/// ```
/// assert_eq!(tricept_model::effects::normalised_coordinate(750.0, 600.0, 900.0), 0.0);
/// assert_eq!(tricept_model::effects::normalised_coordinate(900.0, 600.0, 900.0), 1.0);
/// ```
pub fn normalised_coordinate(x: f64, lo: f64, hi: f64) -> f64 {
    if hi > lo {
        (2.0 * x - lo - hi) / (hi - lo)
    } else {
        0.0
    }
}

/// Legendre polynomial `P2(x) = (3 x^2 - 1) / 2`: the quadratic shape with
/// no constant or linear part over `[-1, 1]` (those are absorbed by a leg
/// offset and a lead).
pub fn legendre_p2(x: f64) -> f64 {
    0.5 * (3.0 * x * x - 1.0)
}

/// Legendre polynomial `P3(x) = (5 x^3 - 3 x) / 2`.
pub fn legendre_p3(x: f64) -> f64 {
    0.5 * (5.0 * x * x * x - 3.0 * x)
}

/// Legendre polynomial `P4(x) = (35 x^4 - 30 x^2 + 3) / 8`.
pub fn legendre_p4(x: f64) -> f64 {
    let x2 = x * x;
    (35.0 * x2 * x2 - 30.0 * x2 + 3.0) / 8.0
}

/// Reading error of an encoder with gain error `ppm` at `angle_rad`, rad.
///
/// # Example
/// ```
/// // 200 ppm at 0.3 rad: 60 urad, 12.4 arcsec.
/// assert!((tricept_model::effects::encoder_gain_error_rad(200.0, 0.3) - 6e-5).abs() < 1e-18);
/// ```
pub fn encoder_gain_error_rad(ppm: f64, angle_rad: f64) -> f64 {
    ppm * 1e-6 * angle_rad
}

/// A quantity drifting linearly by `amount` over the campaign, at
/// `fraction` of it (any unit: the result has `amount`'s).
pub fn linear_drift(amount: f64, fraction: f64) -> f64 {
    amount * fraction
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
