//! How the effects are put into a simulated machine: an [`Effect`] is one
//! effect's input (its magnitude, in the units a machine builder quotes,
//! not the diagnosis' parameters) with the hooks its own file gives it
//! ([`Simulate`]). The plant calls every effect's hooks at each stage (the
//! machine's kinematics, the temperature, the legs, the readings, the
//! logged rows) and names none of them.
//!
//! Each effect is one file. The effects of the vocabulary
//! ([`tricept_model::effects`]) carry their simulation in their registry
//! spec ([`EffectSpec::simulation`](tricept_model::effects::EffectSpec)),
//! and their inputs are [`tricept_model::effects::simulated`] (re-exported
//! here). The effects *outside* the vocabulary, which the diagnosis can
//! only describe through its generic dictionary
//! ([`tricept_model::effects::GenericFamily`]) or report as unknown, have
//! their files here, each listed once in [`OUTSIDE`]:
//!
//! | name | magnitude |
//! |---|---|
//! | `leg-periodic` | `um` per leg, `period_mm`, `phase_deg` per leg, `waveform` (`sine` or `sawtooth`) |
//! | `leg-quadratic` | `um` per leg at `half_width_mm` from `centre_mm` |
//! | `leg-power` | `um` per leg at `half_width_mm` from `centre_mm`, `exponent` (a shape outside the dictionary for 1.5) |
//! | `leg-step` | `um` per leg inside the worn segment of commands `from_mm` to `to_mm` |
//! | `scale-drift` | `um` over the campaign, linear in time |
//! | `encoder-gain` | `phi_ppm`, `theta_ppm` |
//!
//! An effect is written in JSON as its tag and its keys
//! (`{"effect":"leg-lead","ppm":[50,-30,40]}`: what `simulate
//! --truth-effect` takes); `tricept effects` lists every effect's keys,
//! their units and meaning ([`Effect::keys`]) and an example of each at a
//! typical size ([`typical_effects`]).

use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use tricept_data::MeasuredPose;
use tricept_kinematics::{Machine, up_limb::UpJoints};
use tricept_model::effects::{CauseName, EffectName, Simulate, Simulation};

pub use tricept_model::effects::simulated::*;
pub use tricept_model::effects::{EffectKey, PoseState};

mod encoder_gain;
mod leg_periodic;
mod leg_power;
mod leg_quadratic;
mod leg_step;
mod scale_drift;

pub use encoder_gain::EncoderGain;
pub use leg_periodic::{LegPeriodic, Waveform};
pub use leg_power::LegPower;
pub use leg_quadratic::LegQuadratic;
pub use leg_step::LegStep;
pub use scale_drift::ScaleDrift;

/// The simulator's effects outside the vocabulary, in the order
/// `tricept effects` lists them.
pub const OUTSIDE: [&Simulation; 6] = [
    &leg_periodic::SIMULATION,
    &leg_quadratic::SIMULATION,
    &leg_power::SIMULATION,
    &leg_step::SIMULATION,
    &scale_drift::SIMULATION,
    &encoder_gain::SIMULATION,
];

/// Every effect the simulator knows, in the order `tricept effects` lists
/// them: the terms of the vocabulary, the effects outside it, then the
/// vocabulary's rows set aside (outliers).
pub fn simulations() -> Vec<&'static Simulation> {
    let vocabulary = |terms: bool| {
        EffectName::ALL
            .into_iter()
            .filter(move |e| e.is_term() == terms)
            .map(|e| &e.spec().simulation)
    };
    vocabulary(true)
        .chain(OUTSIDE)
        .chain(vocabulary(false))
        .collect()
}

/// One unmodelled effect with its magnitude.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r##"
# Example
```
use tricept_plant::Effect;
use tricept_plant::effects::LegLead;
let e = Effect::from(LegLead { ppm: [50.0, -30.0, 40.0] });
assert_eq!(serde_json::to_string(&e).unwrap(), r#"{"effect":"leg-lead","ppm":[50.0,-30.0,40.0]}"#);
let back: Effect = serde_json::from_str(r#"{"effect":"leg-lead","ppm":[50,-30,40]}"#).unwrap();
assert_eq!(back, e);
```
"##
)]
pub struct Effect(Box<dyn Simulate>);

impl<T: Simulate + 'static> From<T> for Effect {
    fn from(input: T) -> Effect {
        Effect(Box::new(input))
    }
}

impl Clone for Effect {
    fn clone(&self) -> Effect {
        Effect(self.0.clone_box())
    }
}

impl std::fmt::Debug for Effect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl PartialEq for Effect {
    fn eq(&self, other: &Effect) -> bool {
        self.tag() == other.tag()
            && matches!((self.0.to_json(), other.0.to_json()), (Ok(a), Ok(b)) if a == b)
    }
}

impl Effect {
    /// What the effect's file says about its simulation.
    pub fn simulation(&self) -> &'static Simulation {
        self.0.simulation()
    }

    /// The input, if it is of type `T`.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_plant::Effect;
use tricept_plant::effects::{ScaleDrift, ScaleGain};
let e = Effect::from(ScaleGain { ppm: 50.0 });
assert_eq!(e.input::<ScaleGain>().map(|g| g.ppm), Some(50.0));
assert!(e.input::<ScaleDrift>().is_none());
```
"#
    )]
    pub fn input<T: 'static>(&self) -> Option<&T> {
        self.0.as_any().downcast_ref::<T>()
    }

    /// The JSON object: the tag, then the keys in the order of the input.
    fn to_json(&self) -> Result<serde_json::Map<String, serde_json::Value>, serde_json::Error> {
        let mut map = serde_json::Map::new();
        map.insert("effect".into(), self.tag().into());
        match self.0.to_json()? {
            serde_json::Value::Object(keys) => map.extend(keys),
            other => {
                return Err(serde_json::Error::custom(format!(
                    "the input of `{}` is not a JSON object: {other}",
                    self.tag()
                )));
            }
        }
        Ok(map)
    }

    /// Checks the magnitudes: every number finite and within ±1e6 (in its
    /// key's unit), stiffnesses, periods, widths and exponents positive
    /// ([`EffectKey::positive`]); the error says which key is wrong.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_plant::Effect;
use tricept_plant::effects::LegPower;
let shape = |exponent| LegPower { um: [30.0, -20.0, 25.0], exponent, centre_mm: 845.0, half_width_mm: 250.0 };
assert!(Effect::from(shape(1.5)).validate().is_ok());
let e = Effect::from(shape(-1.5)).validate().unwrap_err();
assert!(e.contains("exponent"), "{e}");
```
"#
    )]
    pub fn validate(&self) -> Result<(), String> {
        const LIMIT: f64 = 1e6;
        let map = self.to_json().map_err(|e| e.to_string())?;
        for (key, v) in &map {
            let numbers: Vec<f64> = match v {
                serde_json::Value::Number(n) => n.as_f64().into_iter().collect(),
                serde_json::Value::Array(a) => a.iter().filter_map(|x| x.as_f64()).collect(),
                // A non-finite number serialises as null.
                serde_json::Value::Null => vec![f64::NAN],
                _ => continue,
            };
            let positive = self.keys().iter().any(|k| k.key == key && k.positive);
            for x in numbers {
                if !(x.is_finite() && x.abs() <= LIMIT) {
                    return Err(format!(
                        "`{key}`: {x} is not a finite number within ±{LIMIT:e}"
                    ));
                }
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
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_plant::Effect;
use tricept_plant::effects::{ScaleDrift, ScaleGain};
use tricept_model::effects::{EffectName, GenericFamily};
assert!(Effect::from(ScaleGain { ppm: 50.0 }).name() == EffectName::ScaleGain);
assert!(Effect::from(ScaleDrift { um: 3.0 }).name() == GenericFamily::ReadingDrift);
```
"#
    )]
    pub fn name(&self) -> CauseName {
        let s = self.simulation();
        // Never the fallback: a test checks that every declared cause is a
        // name (tests/listing_tests below).
        s.cause
            .parse()
            .unwrap_or(CauseName::Catalogue(EffectName::Outliers))
    }

    /// The effect's JSON tag (`leg-lead`), as `--truth-effect` takes it.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_plant::Effect;
use tricept_plant::effects::ScaleGain;
assert_eq!(Effect::from(ScaleGain { ppm: 50.0 }).tag(), "scale-gain");
```
"#
    )]
    pub fn tag(&self) -> &'static str {
        self.simulation().tag
    }

    /// The keys this effect takes, with units and meaning.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_plant::Effect;
use tricept_plant::effects::Thermal;
let keys = Effect::from(Thermal { drift_k: 3.0, expansion_ppm_per_k: 11.5 }).keys();
assert_eq!(keys[1].key, "expansion_ppm_per_k");
assert_eq!(keys[1].unit, "ppm/K");
```
"#
    )]
    pub fn keys(&self) -> &'static [EffectKey] {
        self.simulation().keys
    }

    /// Whether the effect is in the diagnosis' vocabulary (named as itself)
    /// rather than outside it (described by a generic family).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_plant::Effect;
use tricept_plant::effects::{ScaleDrift, ScaleGain};
assert!(Effect::from(ScaleGain { ppm: 50.0 }).in_vocabulary());
assert!(!Effect::from(ScaleDrift { um: 4.0 }).in_vocabulary());
```
"#
    )]
    pub fn in_vocabulary(&self) -> bool {
        matches!(self.name(), CauseName::Catalogue(_))
    }

    /// Changes the actual machine's kinematics (class-2 errors).
    pub(crate) fn modify_machine(&self, m: &mut Machine) {
        self.0.modify_machine(m);
    }

    /// Temperature change (K) at `fraction` (0..1) of the campaign.
    pub(crate) fn temperature_drift_k(&self, fraction: f64) -> f64 {
        self.0.temperature_drift_k(fraction)
    }

    /// Adds this effect's extra length to the legs (mm).
    pub(crate) fn extra_leg_length(&self, nominal: &Machine, s: &PoseState, legs: &mut [f64; 3]) {
        self.0.extra_leg_length(nominal, s, legs);
    }

    /// Adds this effect's reading errors to clean readings `r` (rad, rad, mm)
    /// taken with the UP limb truly at `up`, at pose state `s`.
    pub(crate) fn reading_error(&self, s: &PoseState, up: &UpJoints, r: &mut [f64; 3]) {
        self.0.reading_error(s, up, r);
    }

    /// Corrupts logged rows after noise (outliers). `sigma` is the logged
    /// noise per channel.
    pub(crate) fn corrupt_readings(&self, poses: &mut [MeasuredPose], seed: u64, sigma: &[f64; 3]) {
        let mut readings: Vec<[f64; 3]> = poses.iter().map(|p| p.readings.to_array()).collect();
        self.0.corrupt_readings(&mut readings, seed, sigma);
        for (p, r) in poses.iter_mut().zip(readings) {
            if p.readings.to_array() != r {
                p.readings = tricept_data::Readings::from_array(r);
            }
        }
    }
}

impl Serialize for Effect {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::Error as _;
        self.to_json()
            .map_err(S::Error::custom)?
            .serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Effect {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Effect, D::Error> {
        let mut map = serde_json::Map::<String, serde_json::Value>::deserialize(deserializer)?;
        let tag = match map.remove("effect") {
            Some(serde_json::Value::String(tag)) => tag,
            Some(other) => {
                return Err(D::Error::custom(format!(
                    "invalid type: {other}, expected the effect's name"
                )));
            }
            None => return Err(D::Error::missing_field("effect")),
        };
        let all = simulations();
        let Some(simulation) = all.iter().find(|s| s.tag == tag) else {
            let known: Vec<String> = all.iter().map(|s| format!("`{}`", s.tag)).collect();
            return Err(D::Error::custom(format!(
                "unknown variant `{tag}`, expected one of {}",
                known.join(", ")
            )));
        };
        (simulation.parse)(serde_json::Value::Object(map))
            .map(Effect)
            .map_err(D::Error::custom)
    }
}

/// One effect of every kind the simulator knows, at a typical size (what a
/// real machine of the paper's class might show, or a size the diagnosis'
/// docs use), in the order of [`simulations`].
///
/// # Example
/// ```
/// let all = tricept_plant::effects::typical_effects();
/// assert!(all.iter().any(|e| e.tag() == "leg-step"));
/// for e in &all {
///     assert!(e.validate().is_ok());
/// }
/// ```
pub fn typical_effects() -> Vec<Effect> {
    simulations()
        .into_iter()
        .map(|s| Effect((s.typical)()))
        .collect()
}

#[cfg(test)]
mod listing_tests {
    use super::*;

    #[test]
    fn every_effect_has_one_typical_example_of_its_own_tag() {
        let all = simulations();
        let tags: Vec<&str> = typical_effects().iter().map(Effect::tag).collect();
        assert_eq!(tags, all.iter().map(|s| s.tag).collect::<Vec<_>>());
        let mut unique = tags.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), tags.len(), "{tags:?}");
        assert_eq!(tags.len(), EffectName::ALL.len() + OUTSIDE.len());
        for e in EffectName::ALL {
            let s = &e.spec().simulation;
            assert_eq!(s.tag, e.as_str());
            assert_eq!(s.cause.parse::<CauseName>(), Ok(CauseName::Catalogue(e)));
        }
        for s in OUTSIDE {
            let cause: CauseName = s.cause.parse().unwrap();
            assert!(cause.is_generic(), "{}", s.tag);
        }
        for e in typical_effects() {
            assert_eq!(e.name().as_str(), e.simulation().cause);
        }
    }

    /// (Moved from the doc examples of `validate`, `keys` and
    /// `typical_effects`.)
    #[test]
    fn a_compliance_needs_a_positive_stiffness() {
        let stiffness = |s| {
            Effect::from(Compliance {
                stiffness_n_per_um_at_1m: s,
            })
        };
        assert!(stiffness(33.6).validate().is_ok());
        let e = stiffness(-5.0).validate().unwrap_err();
        assert!(e.contains("stiffness_n_per_um_at_1m"), "{e}");
        let keys = stiffness(33.6).keys();
        assert_eq!(keys[0].key, "stiffness_n_per_um_at_1m");
        assert_eq!(keys[0].unit, "N/um");
        assert!(typical_effects().iter().any(|e| e.tag() == "compliance"));
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
