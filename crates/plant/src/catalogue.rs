//! The simulator's effect keys: every [`Effect`] the plant can hide in a
//! machine, with the keys `simulate --truth-effect` takes, their units and
//! meaning, and an example at a typical size. `tricept effects` prints
//! this listing; docs/diagnosis.md holds the same table.
//!
//! The keys are the *simulator's* inputs, in the units a machine builder
//! quotes (`ppm` of lead, `stiffness_n_per_um_at_1m`), not the parameters
//! the diagnosis fits (`lead1_ppm`, `compliance_um_per_kn_at_1m`). Every
//! variant of [`Effect`] must answer [`Effect::keys`] (the compiler flags a
//! new one) and appear in [`typical_effects`] (a test checks it).

use crate::Effect;
use crate::effects::Waveform;
use tricept_model::effects::CauseName;

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
            Effect::LegQuadratic { .. } => &[
                key!(
                    "um",
                    "um",
                    "error of each leg [3] at half_width_mm from the centre"
                ),
                key!("centre_mm", "mm", "leg length of zero error (default 845)"),
                key!(
                    "half_width_mm",
                    "mm",
                    "distance from the centre at which the error is `um` (default 250)"
                ),
            ],
            Effect::LegPower { .. } => &[
                key!(
                    "um",
                    "um",
                    "error of each leg [3] at half_width_mm from the centre"
                ),
                key!(
                    "exponent",
                    "-",
                    "exponent of |x| (outside the dictionary unless 2)"
                ),
                key!("centre_mm", "mm", "leg length of zero error (default 845)"),
                key!(
                    "half_width_mm",
                    "mm",
                    "distance from the centre at which the error is `um` (default 250)"
                ),
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
/// let all = tricept_plant::catalogue::typical_effects();
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
mod tests {
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
