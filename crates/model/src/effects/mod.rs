//! The vocabulary of effects that the paper's 15-parameter geometric model
//! leaves out: a registry with one file per effect, and their physics as
//! pure functions, in the units a machine builder quotes.
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
//! # The registry
//!
//! Each effect is one file of this module whose [`EffectSpec`] says once:
//! its parameters (name, unit, typical size), its [`Kind`] (leg, reading,
//! kinematic) and what the data must log ([`Needs`]), its columns as
//! `(parameter, Basis, value)` entries when it is linear in its parameters
//! or how it modifies the machine otherwise, where a fitted value goes in a
//! machine file ([`Deployment`]), its physical ranges and why
//! ([`Judged`]), its description, its residual plot ([`PlotAxes`]), its
//! realistic magnitudes and its known aliases. [`EffectName::spec`] is the
//! registry: one line per effect in the `registry!` invocation below. The
//! extended machine, the diagnosis' extended model, its plausibility table,
//! its deployment, the calibration record's check, [`UnknownEffect`] and
//! the CLI help iterate it; no other code names an effect to classify it.
//!
//! Each file also says how the plant simulator puts its effect into a
//! machine ([`Simulation`], in the spec): the `--truth-effect` input type
//! with its keys and units (re-exported as [`simulated`]`::LegLead`, ...)
//! and its [`Simulate`] hooks (kinematics, temperature, leg lengths,
//! readings, logged rows), which the plant calls without naming any
//! effect.
//!
//! Adding an effect: its file here (with its simulation), its registry
//! line and its docs; the compiler flags anything else.
//!
//! The same functions serve the plant simulator (which applies them to a
//! simulated machine) and the diagnosis (which fits them to measured data),
//! so that what is looked for is exactly what is simulated. Neither needs
//! the other: diagnosing real data does not depend on the simulator.
//!
//! Beyond the vocabulary, the diagnosis searches a dictionary of *generic*
//! terms ([`GenericFamily`], `generic.rs`: periodic and polynomial
//! leg-length errors, drifts with time or temperature, encoder gains, scale
//! non-linearity, sensor reversal errors) so that an effect outside the
//! vocabulary is described in physical words rather than mistaken for a
//! known one. Their functional forms ([`periodic_extra_mm`],
//! [`legendre_p2`], [`encoder_gain_error_rad`], [`linear_drift`], ...) are
//! there too: the simulator's out-of-vocabulary effects use them. A report
//! names either kind by a [`CauseName`].

use serde::{Deserialize, Serialize};

mod deployment;
mod forms;
mod generic;
mod simulation;
mod spec;

pub use deployment::{pose_free_leg_extra_per_mm, static_leg_extra_per_mm};
pub use forms::{
    encoder_gain_error_rad, legendre_p2, legendre_p3, legendre_p4, linear_drift,
    normalised_coordinate, periodic_extra_mm, segment_extra_mm,
};
pub use generic::{GenericFamily, GenericSpec};
pub use simulation::{EffectKey, PoseState, Simulate, SimulateObject, Simulation, parse_input};
pub use spec::{
    Basis, CHANNELS, CheckColumns, CheckRole, CheckWhen, CommonPart, Deployment, EffectSpec,
    Entries, Judged, Judgement, Kind, KnownAlias, LegContext, LegDeployment, Magnitude, Measure,
    Needs, Parameter, PlausibleRange, PlotAxes, Structural, XAxis, YAxis,
};

/// The registry: the enum of the vocabulary (its variants in this order,
/// each with its doc) and, for each, the module whose `SPEC` says the rest.
macro_rules! registry {
    ($($(#[$doc:meta])* $variant:ident => $module:ident,)*) => {
        $(mod $module;)*

        /// The vocabulary of the diagnosis report.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
        #[serde(rename_all = "kebab-case")]
        pub enum EffectName {
            $($(#[$doc])* $variant,)*
        }

        /// The simulator's input of each effect, named as its variant
        /// (`simulated::LegLead { ppm }`): its magnitude in the units a
        /// machine builder quotes, with its [`Simulate`] hooks.
        pub mod simulated {
            $(pub use crate::effects::$module::$variant;)*
        }

        impl EffectName {
            /// Every effect, in the order of the vocabulary's table.
            pub const ALL: [EffectName; [$(EffectName::$variant),*].len()] =
                [$(EffectName::$variant),*];

            /// What the registry says about the effect.
            ///
            /// # Example
            /// ```
            /// # use tricept_model::effects::{Deployment, EffectName};
            /// let s = EffectName::Compliance.spec();
            /// assert_eq!(s.name, "compliance");
            /// assert!(matches!(s.deployment, Deployment::LegEffects(_)));
            /// ```
            pub fn spec(self) -> &'static EffectSpec {
                match self {
                    $(EffectName::$variant => &$module::SPEC,)*
                }
            }
        }
    };
}

registry! {
    /// Ball-screw lead error of the actuated legs.
    LegLead => leg_lead,
    /// Lost motion of the actuated legs.
    Backlash => backlash,
    /// Thermal growth of the legs during a temperature drift.
    Thermal => thermal,
    /// Gain error of the UP limb's linear scale.
    ScaleGain => scale_gain,
    /// Once-per-revolution error of the U-joint encoders.
    EncoderEccentricity => encoder_eccentricity,
    /// Class-2 errors of the UP limb's U joint.
    UjointAxes => ujoint_axes,
    /// Platform twist about the UP limb's axis.
    TubeTwist => tube_twist,
    /// Gravity-induced axial deflection of the legs.
    Compliance => compliance,
    /// Gross reading errors.
    Outliers => outliers,
}

pub use backlash::backlash_extra_mm;
pub use compliance::{
    GRAVITY_M_PER_S2, compliance_extra_mm, gravity_leg_tension_n, stiffness_for_platform_deflection,
};
pub use encoder_eccentricity::eccentricity_error_rad;
pub use leg_lead::leg_lead_extra_mm;
pub use scale_gain::scale_gain_error_mm;
pub use thermal::{REFERENCE_TEMPERATURE_C, thermal_extra_mm};
pub use tube_twist::{add_tube_twist, twist_reference_mm};
pub use ujoint_axes::add_ujoint_axis_errors;

impl EffectName {
    /// Names of the parameters that describe the effect in a model, with
    /// their units (the diagnosis and the fused identification prefix them
    /// with the effect's name: `leg-lead.lead1_ppm`).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_model::effects::EffectName;
assert_eq!(EffectName::ScaleGain.parameter_names(), ["scale_gain_ppm"]);
assert!(EffectName::Outliers.parameter_names().is_empty());
```
"#
    )]
    pub fn parameter_names(self) -> Vec<&'static str> {
        self.spec().parameters.iter().map(|p| p.name).collect()
    }

    /// Number of parameters in a model.
    pub fn parameter_count(self) -> usize {
        self.spec().parameters.len()
    }

    /// The report name (`leg-lead`, ...).
    pub fn as_str(self) -> &'static str {
        self.spec().name
    }

    /// Whether the effect is a term of a model (every effect but the rows
    /// set aside as outliers).
    pub fn is_term(self) -> bool {
        !matches!(self.spec().kind, Kind::Rows)
    }

    /// The effects that are terms of a model, in registry order.
    pub fn terms() -> impl Iterator<Item = EffectName> {
        EffectName::ALL.into_iter().filter(|e| e.is_term())
    }

    /// The structural aliases of the registry: `(effect with the common
    /// part, effect whose parameter it reads as, how)`, each declared by the
    /// second ([`KnownAlias::structural`]).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_model::effects::EffectName;
let (common, other, s) = EffectName::structural_aliases().next().unwrap();
assert_eq!((common.as_str(), other.as_str()), ("leg-lead", "scale-gain"));
assert!(common.spec().common_part.is_some());
assert!((s.says)(50.0, 2.0).contains("50.0"));
```
"#
    )]
    pub fn structural_aliases()
    -> impl Iterator<Item = (EffectName, EffectName, &'static Structural)> {
        EffectName::ALL.into_iter().flat_map(|other| {
            other.spec().aliases.iter().filter_map(move |a| {
                let s = a.structural.as_ref()?;
                let common = s.common_of.parse::<EffectName>().ok()?;
                Some((common, other, s))
            })
        })
    }

    /// Its judged quantities ([`EffectSpec::plausible`]), each with its
    /// label (the parameter's name unless the spec gives one).
    pub fn judgements(self) -> Vec<Judgement> {
        let s = self.spec();
        s.plausible
            .iter()
            .flat_map(|j| {
                j.of.iter().map(move |(measure, label)| Judgement {
                    range: j.range,
                    measure: *measure,
                    label: match (measure, label.is_empty()) {
                        (Measure::Parameter(i), true) => s
                            .parameters
                            .get(*i)
                            .map_or_else(String::new, |p| p.name.to_string()),
                        _ => label.to_string(),
                    },
                })
            })
            .collect()
    }
}

impl std::str::FromStr for EffectName {
    type Err = UnknownEffect;

    /// Parses a report name.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_model::effects::EffectName;
assert_eq!("leg-lead".parse::<EffectName>(), Ok(EffectName::LegLead));
assert!("pitch".parse::<EffectName>().is_err());
```
"#
    )]
    fn from_str(s: &str) -> Result<EffectName, UnknownEffect> {
        EffectName::ALL
            .into_iter()
            .find(|e| e.as_str() == s)
            .ok_or_else(|| UnknownEffect(s.to_string()))
    }
}

/// A name that is not in the vocabulary.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
let e = "pitch".parse::<tricept_model::effects::EffectName>().unwrap_err();
assert!(e.to_string().starts_with("unknown effect `pitch` (known: leg-lead, backlash,"));
```
"#
)]
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownEffect(pub String);

impl std::fmt::Display for UnknownEffect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let known: Vec<&str> = EffectName::ALL.iter().map(|e| e.as_str()).collect();
        write!(
            f,
            "unknown effect `{}` (known: {})",
            self.0,
            known.join(", ")
        )
    }
}

impl std::error::Error for UnknownEffect {}

impl std::str::FromStr for GenericFamily {
    type Err = UnknownEffect;

    fn from_str(s: &str) -> Result<GenericFamily, UnknownEffect> {
        GenericFamily::ALL
            .into_iter()
            .find(|e| e.as_str() == s)
            .ok_or_else(|| UnknownEffect(s.to_string()))
    }
}

impl std::fmt::Display for EffectName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The name of a cause in a report: an effect of the vocabulary or a
/// generic family. Serialised as the bare kebab-case name.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_model::effects::{CauseName, EffectName, GenericFamily};
let c = CauseName::Catalogue(EffectName::Thermal);
assert!(c == EffectName::Thermal);
assert_eq!(serde_json::to_value(CauseName::Generic(GenericFamily::LegPeriodic)).unwrap(), "leg-periodic");
assert_eq!("reading-drift".parse::<CauseName>().unwrap().to_string(), "reading-drift");
```
"#
)]
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

    /// What the campaign must log for it to be seen.
    pub fn needs(self) -> Needs {
        match self {
            CauseName::Catalogue(e) => e.spec().needs,
            CauseName::Generic(g) => g.spec().needs,
        }
    }

    /// Its known aliases.
    pub fn known_aliases(self) -> &'static [KnownAlias] {
        match self {
            CauseName::Catalogue(e) => e.spec().aliases,
            CauseName::Generic(g) => g.spec().aliases,
        }
    }

    /// The known alias between `self` and `other`, declared by either
    /// (its [`KnownAlias::with`] names the other).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_model::effects::{CauseName, EffectName};
let lead = CauseName::Catalogue(EffectName::LegLead);
let gain = CauseName::Catalogue(EffectName::ScaleGain);
assert!(lead.known_alias(gain).unwrap().why.contains("scale gain"));
assert!(lead.known_alias(lead).is_none());
```
"#
    )]
    pub fn known_alias(self, other: CauseName) -> Option<&'static KnownAlias> {
        self.known_aliases()
            .iter()
            .find(|a| a.with == other.as_str())
            .or_else(|| {
                other
                    .known_aliases()
                    .iter()
                    .find(|a| a.with == self.as_str())
            })
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The registry is consistent: each spec's name is its variant's serde
    /// name, leg effects give leg entries only and reading effects reading
    /// entries, one or more per parameter, every judged measure refers to a
    /// parameter, and every known alias is declared once.
    #[test]
    fn the_registry_is_consistent() {
        let m = tricept_kinematics::Machine::paper();
        let ik = m
            .inverse(&nalgebra::Vector3::new(40.0, -30.0, 760.0))
            .unwrap();
        let at = LegContext {
            nominal: &m,
            commands_mm: ik.legs_mm,
            approach: Some([1, -1, 1]),
            temperature_c: Some(23.0),
        };
        for e in EffectName::ALL {
            let s = e.spec();
            assert_eq!(serde_json::to_value(e).unwrap(), s.name);
            assert_eq!(s.name.parse::<EffectName>(), Ok(e));
            assert_eq!(s.simulation.tag, s.name);
            assert_eq!(s.simulation.cause, s.name);
            let k = s.parameters.len();
            let entries = match s.kind {
                Kind::Leg(f) => Some((f(&at).unwrap(), true)),
                Kind::Reading(f) => Some((f(&ik.up), false)),
                Kind::Kinematic(apply) => {
                    let mut changed = m.clone();
                    apply(&mut changed, &vec![1.0; k]);
                    assert_ne!(changed, m, "{e}");
                    None
                }
                Kind::Rows => {
                    assert_eq!(k, 0);
                    None
                }
            };
            if let Some((entries, legs)) = entries {
                for p in 0..k {
                    assert!(entries.iter().any(|(q, _, _)| *q == p), "{e} {p}");
                }
                for (p, b, v) in entries {
                    assert!(p < k && v.is_finite() && v != 0.0, "{e}");
                    assert_eq!(matches!(b, Basis::Leg(_)), legs, "{e}");
                }
            }
            for j in e.judgements() {
                if let Measure::Parameter(i) | Measure::Amplitude(i, _) = j.measure {
                    assert!(i < k && !j.label.is_empty(), "{e}");
                }
            }
            for a in s.aliases {
                if let Some(st) = &a.structural {
                    assert_eq!(st.common_of, a.with, "{e}");
                    let common: EffectName = st.common_of.parse().unwrap();
                    assert!(common.spec().common_part.is_some(), "{e}");
                    assert_eq!(k, 1, "{e}");
                }
                let other: CauseName = a.with.parse().unwrap();
                assert!(
                    other.known_aliases().iter().all(|b| b.with != s.name),
                    "{e} and {other} both declare their alias"
                );
            }
            if s.fused {
                assert!(matches!(s.kind, Kind::Leg(_) | Kind::Reading(_)), "{e}");
                assert_eq!(s.needs, Needs::Nothing, "{e}");
            }
            for case in (s.realistic)(&m) {
                assert_eq!(case.values.len(), k, "{e}");
            }
        }
    }

    #[test]
    fn generic_aliases_name_causes() {
        for g in GenericFamily::ALL {
            for a in g.spec().aliases {
                assert!(a.with.parse::<CauseName>().is_ok(), "{g}: {}", a.with);
            }
        }
    }

    #[test]
    fn unknown_names_list_the_vocabulary() {
        assert_eq!(
            UnknownEffect("x".into()).to_string(),
            "unknown effect `x` (known: leg-lead, backlash, thermal, scale-gain, encoder-eccentricity, ujoint-axes, tube-twist, compliance, outliers)"
        );
    }
}
