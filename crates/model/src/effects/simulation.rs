//! How the plant simulator puts an effect into a simulated machine, said by
//! the effect itself: a [`Simulation`] (its `--truth-effect` tag, the cause
//! a perfect diagnosis names, its input keys with units, its JSON parser
//! and a typical example) and the [`Simulate`] hooks of its input type
//! (the magnitude in the units a machine builder quotes: `ppm`,
//! `stiffness_n_per_um_at_1m`, not the diagnosis' parameters).
//!
//! Every effect of the vocabulary carries its [`Simulation`] in its
//! [`EffectSpec`](super::EffectSpec); the simulator's effects outside the
//! vocabulary carry theirs in the plant. The plant calls the hooks of every
//! effect in order at each stage and names none of them: a hook an effect
//! does not need defaults to doing nothing.

use serde::Serialize;
use serde::de::DeserializeOwned;
use tricept_kinematics::{Machine, up_limb::UpJoints};

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
    /// Whether its values must be positive (a stiffness, a period, a width,
    /// an exponent).
    pub positive: bool,
}

impl EffectKey {
    /// A key whose values may have either sign.
    pub const fn new(key: &'static str, unit: &'static str, meaning: &'static str) -> EffectKey {
        EffectKey {
            key,
            unit,
            meaning,
            positive: false,
        }
    }

    /// A key whose values must be positive.
    pub const fn positive(
        key: &'static str,
        unit: &'static str,
        meaning: &'static str,
    ) -> EffectKey {
        EffectKey {
            key,
            unit,
            meaning,
            positive: true,
        }
    }
}

/// What the effects may depend on at one pose of a simulated campaign.
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

/// The simulator's hooks of one effect's input (its magnitude). Each hook
/// defaults to doing nothing; the plant calls them for every effect, in
/// the order the effects are given.
pub trait Simulate: SimulateObject + std::fmt::Debug + Send + Sync {
    /// What the effect's file says about its simulation.
    fn simulation(&self) -> &'static Simulation;

    /// Changes the actual machine's kinematics (class-2 errors).
    fn modify_machine(&self, _machine: &mut Machine) {}

    /// Temperature change (K) at `fraction` (0..1) of the campaign.
    fn temperature_drift_k(&self, _fraction: f64) -> f64 {
        0.0
    }

    /// Adds the effect's extra length (mm) to the legs at pose `s` of the
    /// machine whose nominal model is `nominal`.
    fn extra_leg_length(&self, _nominal: &Machine, _s: &PoseState, _legs_mm: &mut [f64; 3]) {}

    /// Adds the effect's reading errors to clean readings `r` (rad, rad,
    /// mm) taken with the UP limb truly at `up`, at pose `s`.
    fn reading_error(&self, _s: &PoseState, _up: &UpJoints, _r: &mut [f64; 3]) {}

    /// Corrupts logged readings (rad, rad, mm per row) after the noise;
    /// `sigma` is the logged noise per channel, `seed` the campaign's.
    fn corrupt_readings(&self, _readings: &mut [[f64; 3]], _seed: u64, _sigma: &[f64; 3]) {}
}

/// What every [`Simulate`] type gets from its `Clone` and `Serialize`
/// (implemented for all of them: not to be implemented by hand).
pub trait SimulateObject {
    /// A boxed copy.
    fn clone_box(&self) -> Box<dyn Simulate>;
    /// The input keys and values as a JSON object (without the tag).
    fn to_json(&self) -> Result<serde_json::Value, serde_json::Error>;
    /// As `Any`, to get the input type back.
    fn as_any(&self) -> &dyn std::any::Any;
}

impl<T: Simulate + Clone + Serialize + 'static> SimulateObject for T {
    fn clone_box(&self) -> Box<dyn Simulate> {
        Box::new(self.clone())
    }

    fn to_json(&self) -> Result<serde_json::Value, serde_json::Error> {
        serde_json::to_value(self)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// What an effect's file says about its simulation.
#[derive(Debug, Clone, Copy)]
pub struct Simulation {
    /// Its JSON tag (`leg-lead`), as `--truth-effect` takes it (an effect of
    /// the vocabulary's is its report name).
    pub tag: &'static str,
    /// The report name of the cause a perfect diagnosis would give it: its
    /// name in the vocabulary, or for an effect outside it the generic
    /// family of its form (a name, as [`KnownAlias::with`](super::KnownAlias):
    /// the tests of the registry and of the plant check that it is one).
    pub cause: &'static str,
    /// Its input keys, in the order of its JSON.
    pub keys: &'static [EffectKey],
    /// Reads its input from the JSON object without the tag
    /// ([`parse_input`] of its input type).
    pub parse: fn(serde_json::Value) -> Result<Box<dyn Simulate>, serde_json::Error>,
    /// An example at a typical size (what a real machine of the paper's
    /// class might show, or a size the diagnosis' docs use).
    pub typical: fn() -> Box<dyn Simulate>,
}

/// Reads an effect's input of type `T` from its JSON object (the
/// [`Simulation::parse`] of an effect).
pub fn parse_input<T: Simulate + DeserializeOwned + 'static>(
    value: serde_json::Value,
) -> Result<Box<dyn Simulate>, serde_json::Error> {
    Ok(Box::new(serde_json::from_value::<T>(value)?))
}
