//! How the effects of the vocabulary ([`tricept_model::effects`]) are put
//! into a simulated machine: each [`Effect`] carries its magnitude (in the
//! units a machine builder quotes, not the diagnosis' parameters), maps to
//! its name in the registry in one place ([`Effect::name`]), and the plant
//! applies its physics to the legs, the readings, the machine's kinematics
//! or the logged rows. Every stage matches every effect: a new one is
//! flagged by the compiler wherever it must act, including the listing of
//! `tricept effects` ([`Effect::keys`], [`typical_effects`]): the keys
//! `simulate --truth-effect` takes, their units and meaning, and an
//! example of each at a typical size. (These keys are the simulator's
//! inputs, not the parameters the diagnosis fits: `lead1_ppm`,
//! `compliance_um_per_kn_at_1m`.)
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
//!
//! and effects *outside* the vocabulary, which the diagnosis can only
//! describe through its generic dictionary
//! ([`tricept_model::effects::GenericFamily`]) or report as unknown:
//!
//! | name | magnitude |
//! |---|---|
//! | `leg-periodic` | `um` per leg, `period_mm`, `phase_deg` per leg, `waveform` (`sine` or `sawtooth`) |
//! | `leg-quadratic` | `um` per leg at `half_width_mm` from `centre_mm` |
//! | `leg-power` | `um` per leg at `half_width_mm` from `centre_mm`, `exponent` (a shape outside the dictionary for 1.5) |
//! | `leg-step` | `um` per leg inside the worn segment of commands `from_mm` to `to_mm` |
//! | `scale-drift` | `um` over the campaign, linear in time |
//! | `encoder-gain` | `phi_ppm`, `theta_ppm` |

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};
use tricept_data::MeasuredPose;
use tricept_kinematics::{Machine, UpJoints};
use tricept_model::effects::{
    CauseName, EffectName, GenericFamily, add_tube_twist, add_ujoint_axis_errors,
    backlash_extra_mm, compliance_extra_mm, eccentricity_error_rad, encoder_gain_error_rad,
    gravity_leg_tension_n, leg_lead_extra_mm, linear_drift, normalised_coordinate,
    periodic_extra_mm, scale_gain_error_mm, segment_extra_mm, thermal_extra_mm,
};

/// Shape of a periodic leg-length error.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Waveform {
    /// `A sin(2 pi q / P + psi)`.
    #[default]
    Sine,
    /// A sawtooth of amplitude `A` (rising linearly from `-A` to `A` over
    /// each period, then dropping): a shape outside the dictionary, with
    /// harmonics.
    Sawtooth,
}

fn default_centre_mm() -> f64 {
    845.0
}

fn default_half_width_mm() -> f64 {
    250.0
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
    /// Out of the vocabulary: a leg-length error periodic in the leg length
    /// (ball-screw pitch error), `um_i w(2 pi q_i / P + psi_i)`.
    LegPeriodic {
        /// Amplitude of each leg, um.
        um: [f64; 3],
        /// Period (the screw lead), mm.
        period_mm: f64,
        /// Phase of each leg, deg.
        phase_deg: [f64; 3],
        /// Shape `w` (default sine).
        #[serde(default)]
        waveform: Waveform,
    },
    /// Out of the vocabulary: a leg-length error quadratic in the leg
    /// length, `um_i ((q_i - centre) / half_width)^2`.
    LegQuadratic {
        /// Error of each leg at `half_width_mm` from the centre, um.
        um: [f64; 3],
        /// Leg length of zero error, mm (default 845: the middle of the
        /// paper machine's workspace leg lengths).
        #[serde(default = "default_centre_mm")]
        centre_mm: f64,
        /// Distance from the centre at which the error is `um`, mm
        /// (default 250).
        #[serde(default = "default_half_width_mm")]
        half_width_mm: f64,
    },
    /// Out of the vocabulary (and of the dictionary's forms unless
    /// `exponent` is 2): `um_i |(q_i - centre) / half_width|^exponent`.
    LegPower {
        /// Error of each leg at `half_width_mm` from the centre, um.
        um: [f64; 3],
        /// Exponent of the shape.
        exponent: f64,
        /// Leg length of zero error, mm (default 845).
        #[serde(default = "default_centre_mm")]
        centre_mm: f64,
        /// Distance from the centre at which the error is `um`, mm (default 250).
        #[serde(default = "default_half_width_mm")]
        half_width_mm: f64,
    },
    /// Out of the vocabulary: a worn segment of a leg's ball screw: leg `i`
    /// is `um_i` longer wherever its command lies from `from_mm` to
    /// `to_mm`, and as built elsewhere (a step in and out of the segment).
    LegStep {
        /// Extra length of each leg inside the segment, um.
        um: [f64; 3],
        /// Start of the worn segment, mm of leg command.
        from_mm: f64,
        /// End of the worn segment, mm of leg command.
        to_mm: f64,
    },
    /// Out of the vocabulary: the scale reading drifts linearly with time,
    /// by `um` from the first to the last pose, whatever the temperature.
    ScaleDrift {
        /// Drift over the campaign, um.
        um: f64,
    },
    /// Out of the vocabulary: gain errors of the encoders, which read
    /// `(1 + g) angle`.
    EncoderGain {
        /// Gain error of the phi encoder, ppm.
        phi_ppm: f64,
        /// Gain error of the theta encoder, ppm.
        theta_ppm: f64,
    },
    /// Gross reading errors in a few rows.
    Outliers {
        /// Number of corrupted rows.
        count: usize,
        /// Size of each error in noise standard deviations (random sign).
        size_sigma: f64,
    },
}

/// Adds `um_i |(q_i - centre) / half_width|^exponent` (um) to each leg (mm).
fn add_power_law(
    legs: &mut [f64; 3],
    commands_mm: &[f64; 3],
    um: &[f64; 3],
    exponent: f64,
    centre_mm: f64,
    half_width_mm: f64,
) {
    for i in 0..3 {
        let x = normalised_coordinate(
            commands_mm[i],
            centre_mm - half_width_mm,
            centre_mm + half_width_mm,
        );
        legs[i] += um[i] * 1e-3 * x.abs().powf(exponent);
    }
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
    /// Fraction of the campaign elapsed (0 at the first pose, 1 at the last).
    pub fraction: f64,
}

impl Effect {
    /// Checks the magnitudes: every number finite and within ±1e6 (in its
    /// key's unit), stiffnesses, periods, widths and exponents positive;
    /// the error says which key is wrong.
    ///
    /// # Example
    /// ```
    /// use tricept_plant::Effect;
    /// assert!(Effect::Compliance { stiffness_n_per_um_at_1m: 33.6 }.validate().is_ok());
    /// let e = Effect::Compliance { stiffness_n_per_um_at_1m: -5.0 }.validate().unwrap_err();
    /// assert!(e.contains("stiffness_n_per_um_at_1m"), "{e}");
    /// ```
    pub fn validate(&self) -> Result<(), String> {
        const LIMIT: f64 = 1e6;
        let value = serde_json::to_value(self).map_err(|e| e.to_string())?;
        let serde_json::Value::Object(map) = value else {
            return Ok(());
        };
        for (key, v) in &map {
            let numbers: Vec<f64> = match v {
                serde_json::Value::Number(n) => n.as_f64().into_iter().collect(),
                serde_json::Value::Array(a) => a.iter().filter_map(|x| x.as_f64()).collect(),
                // A non-finite number serialises as null.
                serde_json::Value::Null => vec![f64::NAN],
                _ => continue,
            };
            for x in numbers {
                if !(x.is_finite() && x.abs() <= LIMIT) {
                    return Err(format!(
                        "`{key}`: {x} is not a finite number within ±{LIMIT:e}"
                    ));
                }
                let positive = matches!(
                    key.as_str(),
                    "stiffness_n_per_um_at_1m" | "period_mm" | "half_width_mm" | "exponent"
                );
                if positive && x <= 0.0 {
                    return Err(format!("`{key}` must be positive, got {x}"));
                }
            }
        }
        Ok(())
    }

    /// The name a perfect diagnosis would give this effect: its name in
    /// the vocabulary, or for an effect outside it the generic family of
    /// its form (`leg-power` and the sawtooth `leg-periodic` only
    /// approximately: their shapes are outside the dictionary).
    ///
    /// # Example
    /// ```
    /// use tricept_plant::Effect;
    /// use tricept_model::effects::{EffectName, GenericFamily};
    /// assert!(Effect::ScaleGain { ppm: 50.0 }.name() == EffectName::ScaleGain);
    /// assert!(Effect::ScaleDrift { um: 3.0 }.name() == GenericFamily::ReadingDrift);
    /// ```
    pub fn name(&self) -> CauseName {
        let catalogue = |e| CauseName::Catalogue(e);
        let generic = |g| CauseName::Generic(g);
        match self {
            Effect::LegLead { .. } => catalogue(EffectName::LegLead),
            Effect::Backlash { .. } => catalogue(EffectName::Backlash),
            Effect::Thermal { .. } => catalogue(EffectName::Thermal),
            Effect::ScaleGain { .. } => catalogue(EffectName::ScaleGain),
            Effect::EncoderEccentricity { .. } => catalogue(EffectName::EncoderEccentricity),
            Effect::UjointAxes { .. } => catalogue(EffectName::UjointAxes),
            Effect::TubeTwist { .. } => catalogue(EffectName::TubeTwist),
            Effect::Compliance { .. } => catalogue(EffectName::Compliance),
            Effect::Outliers { .. } => catalogue(EffectName::Outliers),
            Effect::LegPeriodic { .. } => generic(GenericFamily::LegPeriodic),
            Effect::LegQuadratic { .. } | Effect::LegPower { .. } => {
                generic(GenericFamily::LegPolynomial)
            }
            Effect::LegStep { .. } => generic(GenericFamily::LegStep),
            Effect::ScaleDrift { .. } => generic(GenericFamily::ReadingDrift),
            Effect::EncoderGain { .. } => generic(GenericFamily::EncoderGain),
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
            Effect::LegLead { .. }
            | Effect::Backlash { .. }
            | Effect::Thermal { .. }
            | Effect::ScaleGain { .. }
            | Effect::EncoderEccentricity { .. }
            | Effect::Compliance { .. }
            | Effect::LegPeriodic { .. }
            | Effect::LegQuadratic { .. }
            | Effect::LegPower { .. }
            | Effect::LegStep { .. }
            | Effect::ScaleDrift { .. }
            | Effect::EncoderGain { .. }
            | Effect::Outliers { .. } => {}
        }
    }

    /// Temperature change (K) at `fraction` (0..1) of the campaign.
    pub(crate) fn temperature_drift_k(&self, fraction: f64) -> f64 {
        match self {
            Effect::Thermal { drift_k, .. } => drift_k * fraction,
            Effect::LegLead { .. }
            | Effect::Backlash { .. }
            | Effect::ScaleGain { .. }
            | Effect::EncoderEccentricity { .. }
            | Effect::UjointAxes { .. }
            | Effect::TubeTwist { .. }
            | Effect::Compliance { .. }
            | Effect::LegPeriodic { .. }
            | Effect::LegQuadratic { .. }
            | Effect::LegPower { .. }
            | Effect::LegStep { .. }
            | Effect::ScaleDrift { .. }
            | Effect::EncoderGain { .. }
            | Effect::Outliers { .. } => 0.0,
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
            Effect::LegPeriodic {
                um,
                period_mm,
                phase_deg,
                waveform,
            } => {
                for i in 0..3 {
                    let q = s.commands_mm[i];
                    legs[i] += match waveform {
                        Waveform::Sine => {
                            let (sp, cp) = phase_deg[i].to_radians().sin_cos();
                            periodic_extra_mm(um[i] * cp, um[i] * sp, *period_mm, q)
                        }
                        Waveform::Sawtooth => {
                            let turns = q / period_mm + phase_deg[i] / 360.0;
                            um[i] * 1e-3 * (2.0 * (turns - turns.floor()) - 1.0)
                        }
                    };
                }
            }
            Effect::LegQuadratic {
                um,
                centre_mm,
                half_width_mm,
            } => add_power_law(legs, &s.commands_mm, um, 2.0, *centre_mm, *half_width_mm),
            Effect::LegPower {
                um,
                exponent,
                centre_mm,
                half_width_mm,
            } => add_power_law(
                legs,
                &s.commands_mm,
                um,
                *exponent,
                *centre_mm,
                *half_width_mm,
            ),
            Effect::LegStep { um, from_mm, to_mm } => {
                for i in 0..3 {
                    legs[i] += segment_extra_mm(um[i], *from_mm, *to_mm, s.commands_mm[i]);
                }
            }
            Effect::ScaleGain { .. }
            | Effect::EncoderEccentricity { .. }
            | Effect::UjointAxes { .. }
            | Effect::TubeTwist { .. }
            | Effect::ScaleDrift { .. }
            | Effect::EncoderGain { .. }
            | Effect::Outliers { .. } => {}
        }
    }

    /// Adds this effect's reading errors to clean readings `r` (rad, rad, mm)
    /// taken with the UP limb truly at `up`, at pose state `s`.
    pub(crate) fn reading_error(&self, s: &PoseState, up: &UpJoints, r: &mut [f64; 3]) {
        match self {
            Effect::ScaleGain { ppm } => r[2] += scale_gain_error_mm(*ppm, up.q4_mm),
            Effect::ScaleDrift { um } => r[2] += linear_drift(um * 1e-3, s.fraction),
            Effect::EncoderGain { phi_ppm, theta_ppm } => {
                r[0] += encoder_gain_error_rad(*phi_ppm, up.phi_rad);
                r[1] += encoder_gain_error_rad(*theta_ppm, up.theta_rad);
            }
            Effect::EncoderEccentricity {
                phi_arcsec,
                phi_phase_deg,
                theta_arcsec,
                theta_phase_deg,
            } => {
                r[0] += eccentricity_error_rad(*phi_arcsec, *phi_phase_deg, up.phi_rad);
                r[1] += eccentricity_error_rad(*theta_arcsec, *theta_phase_deg, up.theta_rad);
            }
            Effect::LegLead { .. }
            | Effect::Backlash { .. }
            | Effect::Thermal { .. }
            | Effect::UjointAxes { .. }
            | Effect::TubeTwist { .. }
            | Effect::Compliance { .. }
            | Effect::LegPeriodic { .. }
            | Effect::LegQuadratic { .. }
            | Effect::LegPower { .. }
            | Effect::LegStep { .. }
            | Effect::Outliers { .. } => {}
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

// The listing of `tricept effects`: every effect's simulator keys, with
// units and meaning, and a typical example of each.

/// One input key of a simulated effect.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EffectKey {
    /// The JSON key.
    pub key: &'static str,
    /// Its unit (`-` for a count or a shape; `[3]` marks one value per leg
    /// or encoder in the key's description).
    pub unit: &'static str,
    /// What it is, with its default when it may be left out.
    pub meaning: &'static str,
}

/// An [`EffectKey`] literal (a struct literal, so that the slices of
/// [`Effect::keys`] are promoted to `'static`).
macro_rules! key {
    ($key:literal, $unit:literal, $meaning:literal) => {
        EffectKey {
            key: $key,
            unit: $unit,
            meaning: $meaning,
        }
    };
}

impl Effect {
    /// The effect's JSON tag (`leg-lead`), as `--truth-effect` takes it.
    ///
    /// # Example
    /// ```
    /// use tricept_plant::Effect;
    /// assert_eq!(Effect::ScaleGain { ppm: 50.0 }.tag(), "scale-gain");
    /// ```
    pub fn tag(&self) -> &'static str {
        match self {
            Effect::LegLead { .. } => "leg-lead",
            Effect::Backlash { .. } => "backlash",
            Effect::Thermal { .. } => "thermal",
            Effect::ScaleGain { .. } => "scale-gain",
            Effect::EncoderEccentricity { .. } => "encoder-eccentricity",
            Effect::UjointAxes { .. } => "ujoint-axes",
            Effect::TubeTwist { .. } => "tube-twist",
            Effect::Compliance { .. } => "compliance",
            Effect::LegPeriodic { .. } => "leg-periodic",
            Effect::LegQuadratic { .. } => "leg-quadratic",
            Effect::LegPower { .. } => "leg-power",
            Effect::LegStep { .. } => "leg-step",
            Effect::ScaleDrift { .. } => "scale-drift",
            Effect::EncoderGain { .. } => "encoder-gain",
            Effect::Outliers { .. } => "outliers",
        }
    }

    /// The keys this effect takes, with units and meaning.
    ///
    /// # Example
    /// ```
    /// use tricept_plant::Effect;
    /// let keys = Effect::Compliance { stiffness_n_per_um_at_1m: 33.6 }.keys();
    /// assert_eq!(keys[0].key, "stiffness_n_per_um_at_1m");
    /// assert_eq!(keys[0].unit, "N/um");
    /// ```
    pub fn keys(&self) -> &'static [EffectKey] {
        // The keys of the two curved-leg shapes.
        const UM_AT_HALF_WIDTH: EffectKey = key!(
            "um",
            "um",
            "error of each leg [3] at half_width_mm from the centre"
        );
        const CENTRE: EffectKey = key!("centre_mm", "mm", "leg length of zero error (default 845)");
        const HALF_WIDTH: EffectKey = key!(
            "half_width_mm",
            "mm",
            "distance from the centre at which the error is `um` (default 250)"
        );
        match self {
            Effect::LegLead { .. } => &[key!(
                "ppm",
                "ppm",
                "lead error of each leg [3]: the leg grows by ppm 1e-6 q"
            )],
            Effect::Backlash { .. } => &[key!(
                "um",
                "um",
                "lost motion of each leg [3]; with --both-directions the data show it"
            )],
            Effect::Thermal { .. } => &[
                key!(
                    "drift_k",
                    "K",
                    "temperature change from the first pose to the last"
                ),
                key!(
                    "expansion_ppm_per_k",
                    "ppm/K",
                    "the legs' expansion coefficient (steel 11.5; 0 for a temperature log alone)"
                ),
            ],
            Effect::ScaleGain { .. } => &[key!("ppm", "ppm", "gain error of the linear scale")],
            Effect::EncoderEccentricity { .. } => &[
                key!(
                    "phi_arcsec",
                    "arcsec",
                    "once-per-revolution amplitude on the phi encoder"
                ),
                key!("phi_phase_deg", "deg", "its phase"),
                key!("theta_arcsec", "arcsec", "amplitude on the theta encoder"),
                key!("theta_phase_deg", "deg", "its phase"),
            ],
            Effect::UjointAxes { .. } => &[
                key!(
                    "skew_arcsec",
                    "arcsec",
                    "non-orthogonality of the UP limb's U-joint axes"
                ),
                key!("offset_um", "um", "distance between the two axes"),
            ],
            Effect::TubeTwist { .. } => &[key!(
                "arcsec_per_100mm",
                "arcsec/100mm",
                "platform twist about the limb axis per 100 mm of extension from the middle plane"
            )],
            Effect::Compliance { .. } => &[key!(
                "stiffness_n_per_um_at_1m",
                "N/um",
                "axial stiffness of a leg 1 m long (scales as 1/length); loads from the machine file's `loads`"
            )],
            Effect::LegPeriodic { .. } => &[
                key!("um", "um", "amplitude of each leg [3]"),
                key!("period_mm", "mm", "period: the screw lead"),
                key!("phase_deg", "deg", "phase of each leg [3]"),
                key!(
                    "waveform",
                    "-",
                    "`sine` (default) or `sawtooth` (outside the dictionary)"
                ),
            ],
            Effect::LegQuadratic { .. } => &[UM_AT_HALF_WIDTH, CENTRE, HALF_WIDTH],
            Effect::LegPower { .. } => &[
                UM_AT_HALF_WIDTH,
                key!(
                    "exponent",
                    "-",
                    "exponent of |x| (outside the dictionary unless 2)"
                ),
                CENTRE,
                HALF_WIDTH,
            ],
            Effect::LegStep { .. } => &[
                key!(
                    "um",
                    "um",
                    "extra length of each leg [3] inside the worn segment"
                ),
                key!("from_mm", "mm", "start of the worn segment, leg command"),
                key!("to_mm", "mm", "end of the worn segment, leg command"),
            ],
            Effect::ScaleDrift { .. } => &[key!(
                "um",
                "um",
                "drift of the scale reading from the first pose to the last, linear in time"
            )],
            Effect::EncoderGain { .. } => &[
                key!("phi_ppm", "ppm", "gain error of the phi encoder"),
                key!("theta_ppm", "ppm", "gain error of the theta encoder"),
            ],
            Effect::Outliers { .. } => &[
                key!("count", "-", "number of corrupted rows"),
                key!(
                    "size_sigma",
                    "sigma",
                    "size of each error in noise standard deviations (random sign)"
                ),
            ],
        }
    }

    /// Whether the effect is in the diagnosis' vocabulary (named as itself)
    /// rather than outside it (described by a generic family).
    ///
    /// # Example
    /// ```
    /// use tricept_plant::Effect;
    /// assert!(Effect::ScaleGain { ppm: 50.0 }.in_vocabulary());
    /// assert!(!Effect::ScaleDrift { um: 4.0 }.in_vocabulary());
    /// ```
    pub fn in_vocabulary(&self) -> bool {
        matches!(self.name(), CauseName::Catalogue(_))
    }
}

/// One effect of every kind the simulator knows, at a typical size (what a
/// real machine of the paper's class might show, or a size the diagnosis'
/// docs use), in the order of [`Effect`]'s variants.
///
/// # Example
/// ```
/// let all = tricept_plant::effects::typical_effects();
/// assert!(all.iter().any(|e| e.tag() == "compliance"));
/// for e in &all {
///     assert!(e.validate().is_ok());
/// }
/// ```
pub fn typical_effects() -> Vec<Effect> {
    vec![
        Effect::LegLead {
            ppm: [50.0, -30.0, 40.0],
        },
        Effect::Backlash {
            um: [6.0, 5.0, 8.0],
        },
        Effect::Thermal {
            drift_k: 3.0,
            expansion_ppm_per_k: 11.5,
        },
        Effect::ScaleGain { ppm: 50.0 },
        Effect::EncoderEccentricity {
            phi_arcsec: 10.0,
            phi_phase_deg: 30.0,
            theta_arcsec: 8.0,
            theta_phase_deg: -60.0,
        },
        Effect::UjointAxes {
            skew_arcsec: 60.0,
            offset_um: 20.0,
        },
        Effect::TubeTwist {
            arcsec_per_100mm: 30.0,
        },
        Effect::Compliance {
            stiffness_n_per_um_at_1m: 33.6,
        },
        Effect::LegPeriodic {
            um: [4.0, 4.0, 4.0],
            period_mm: 10.0,
            phase_deg: [0.0, 120.0, 240.0],
            waveform: Waveform::Sine,
        },
        Effect::LegQuadratic {
            um: [30.0, -20.0, 25.0],
            centre_mm: 845.0,
            half_width_mm: 250.0,
        },
        Effect::LegPower {
            um: [30.0, -20.0, 25.0],
            exponent: 1.5,
            centre_mm: 845.0,
            half_width_mm: 250.0,
        },
        Effect::LegStep {
            um: [20.0, 0.0, 0.0],
            from_mm: 800.0,
            to_mm: 830.0,
        },
        Effect::ScaleDrift { um: 4.0 },
        Effect::EncoderGain {
            phi_ppm: 100.0,
            theta_ppm: -80.0,
        },
        Effect::Outliers {
            count: 2,
            size_sigma: 300.0,
        },
    ]
}

#[cfg(test)]
mod listing_tests {
    use super::*;

    /// The position of `e`'s variant in [`Effect`]: a new variant makes
    /// this match fail to compile, and the test below then asks for its
    /// typical example.
    fn variant_index(e: &Effect) -> usize {
        match e {
            Effect::LegLead { .. } => 0,
            Effect::Backlash { .. } => 1,
            Effect::Thermal { .. } => 2,
            Effect::ScaleGain { .. } => 3,
            Effect::EncoderEccentricity { .. } => 4,
            Effect::UjointAxes { .. } => 5,
            Effect::TubeTwist { .. } => 6,
            Effect::Compliance { .. } => 7,
            Effect::LegPeriodic { .. } => 8,
            Effect::LegQuadratic { .. } => 9,
            Effect::LegPower { .. } => 10,
            Effect::LegStep { .. } => 11,
            Effect::ScaleDrift { .. } => 12,
            Effect::EncoderGain { .. } => 13,
            Effect::Outliers { .. } => 14,
        }
    }
    const N_VARIANTS: usize = 15;

    #[test]
    fn every_variant_has_one_typical_example_in_order() {
        let all = typical_effects();
        let indices: Vec<usize> = all.iter().map(variant_index).collect();
        assert_eq!(indices, (0..N_VARIANTS).collect::<Vec<_>>());
    }

    #[test]
    fn the_listed_keys_are_exactly_the_serialised_keys() {
        for e in typical_effects() {
            let serde_json::Value::Object(map) = serde_json::to_value(&e).unwrap() else {
                panic!("{e:?} does not serialise to an object");
            };
            assert_eq!(map["effect"], e.tag(), "{e:?}");
            let mut serialised: Vec<&str> = map
                .keys()
                .map(String::as_str)
                .filter(|k| *k != "effect")
                .collect();
            let mut listed: Vec<&str> = e.keys().iter().map(|k| k.key).collect();
            serialised.sort_unstable();
            listed.sort_unstable();
            assert_eq!(serialised, listed, "{}", e.tag());
            assert!(e.validate().is_ok(), "{}", e.tag());
            let back: Effect = serde_json::from_value(serde_json::Value::Object(map)).unwrap();
            assert_eq!(back, e);
        }
    }
}
