//! The effects a simulated machine can hide (`tricept effects`): each one's
//! keys, their units and a typical example (what `simulate
//! --truth-effect` takes), and whether the diagnosis names it (in its
//! vocabulary) or describes it through a generic family.
//!
//! # Example
//! ```
//! use tricept_ident::effects::effects;
//! let all = effects(None)?;
//! assert!(all.effects().len() > 5);
//! # Ok::<(), tricept_ident::Error>(())
//! ```

use serde_json::{Value, json};
use tricept_plant::effects::typical_effects;

use crate::error::{EXIT_OK, Error};

/// What an entry of an effect's columns changes: a leg's length or a
/// reading channel (0 `phi`, 1 `theta`, 2 `s`).
///
/// # Example
/// ```
/// use tricept_ident::effects::{Basis, EffectName, Kind, LegContext};
/// use tricept_ident::kinematics::GeometricMachine;
/// let nominal = GeometricMachine::paper();
/// let at = LegContext { nominal: &nominal, commands_mm: [800.0; 3], approach: None, temperature_c: None };
/// let Kind::Leg(columns) = EffectName::LegLead.spec().kind else { unreachable!() };
/// let legs: Vec<Basis> = columns(&at).map_err(|e| e.to_string())?.iter().map(|e| e.1).collect();
/// assert_eq!(legs, [Basis::Leg(0), Basis::Leg(1), Basis::Leg(2)]); // a leg effect moves legs only
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::Basis;
/// The name a diagnosis reports a cause under: an effect of its vocabulary
/// or a generic family.
///
/// # Example
/// ```
/// use tricept_ident::effects::{CauseName, EffectName, GenericFamily};
/// let lead = CauseName::Catalogue(EffectName::LegLead);
/// assert_eq!((lead.as_str(), lead.is_generic()), ("leg-lead", false));
/// assert_eq!(lead.catalogue(), Some(EffectName::LegLead));
/// let drift = CauseName::Generic(GenericFamily::ReadingDrift);
/// assert_eq!((drift.as_str(), drift.is_generic()), ("reading-drift", true));
/// ```
#[doc(inline)]
pub use tricept_model::effects::CauseName;
/// The columns an effect adds to `tricept check`'s fit: per leg (of the
/// command and temperature) or per reading.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, CheckColumns};
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// let CheckColumns::Legs(extra_mm) = lead.check.as_ref().ok_or("not checked")?.columns else { unreachable!() };
/// assert!((extra_mm(1000.0, 20.0) - 0.001).abs() < 1e-15); // 1 ppm of 1 m
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::CheckColumns;
/// The part an effect plays in `tricept check`: its name, parameters, when
/// it is fitted, and its columns.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, CheckRole, CheckWhen};
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// let role: &CheckRole = lead.check.as_ref().ok_or("not checked")?;
/// assert_eq!(role.parameters, ["lead_ppm"]);
/// assert_eq!(role.when, CheckWhen::WithoutTemperatures);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::CheckRole;
/// When `tricept check` fits an effect: always, with temperatures or without.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, CheckWhen};
/// let when: Vec<CheckWhen> = EffectName::ALL.iter().filter_map(|n| n.spec().check.as_ref()).map(|c| c.when).collect();
/// assert!(when.contains(&CheckWhen::WithoutTemperatures));
/// ```
#[doc(inline)]
pub use tricept_model::effects::CheckWhen;
/// The one-parameter part of an effect equal on all legs (a common lead is
/// also a scale error).
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, CommonPart};
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// let common: &CommonPart = lead.common_part.as_ref().ok_or("no common part")?;
/// assert_eq!(common.parameter, "lead_ppm (every leg)");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::CommonPart;
/// Where a fitted effect goes in a calibrated machine file.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, Deployment};
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// assert!(matches!(lead.deployment, Deployment::LegEffects(_)));
/// assert!(lead.deployment.label().contains("applied by ik"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::Deployment;
/// One input key of a simulated effect (`--truth-effect`): its JSON key,
/// unit and meaning, and whether its values must be positive.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectKey, effects};
/// let list = effects(Some("leg-lead"))?;
/// let keys: &[EffectKey] = list.effects()[0].keys();
/// let json = list.to_json();
/// assert_eq!(json[0]["keys"][0]["key"], keys[0].key); // `tricept effects --json` lists them
/// assert!(keys.iter().all(|k| !k.unit.is_empty() && !k.meaning.is_empty()));
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::EffectKey;
/// The diagnosis' vocabulary of effects.
///
/// # Example
/// ```
/// use tricept_ident::effects::EffectName;
/// let lead: EffectName = "leg-lead".parse()?;
/// assert_eq!(lead.spec().name, "leg-lead");
/// assert!(EffectName::ALL.contains(&lead));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::EffectName;
/// What the diagnosis knows of an effect ([`EffectName::spec`]): its physics,
/// parameters with units, what a campaign must log, where a fit of it goes.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, EffectSpec, Needs};
/// let lead: &EffectSpec = "leg-lead".parse::<EffectName>()?.spec();
/// assert_eq!(lead.parameters.len(), 3); // one per leg
/// assert_eq!(lead.needs, Needs::Nothing);
/// assert_eq!(lead.name, "leg-lead");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::EffectSpec;
/// A family of generic terms: what the diagnosis fits when no effect of
/// its vocabulary explains the data (in JSON, kebab-case).
///
/// # Example
/// ```
/// use tricept_ident::effects::{GenericFamily, Needs};
/// assert_eq!(GenericFamily::ReadingDrift.to_string(), "reading-drift");
/// assert_eq!(serde_json::to_value(GenericFamily::LegStep)?, "leg-step");
/// assert_eq!(GenericFamily::ReadingDrift.spec().needs, Needs::PoseOrder); // a drift needs time
/// # Ok::<(), serde_json::Error>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::GenericFamily;
/// What the diagnosis knows of a generic family
/// ([`GenericFamily::spec`]): its name, whether it acts on legs, what it
/// needs, its plausible ranges, where a fit of it goes.
///
/// # Example
/// ```
/// use tricept_ident::effects::{GenericFamily, GenericSpec};
/// for family in GenericFamily::ALL {
///     let spec: &GenericSpec = family.spec();
///     assert_eq!(spec.name, family.to_string());
/// }
/// assert!(GenericFamily::LegPolynomial.spec().acts_on_legs);
/// assert!(!GenericFamily::EncoderGain.spec().acts_on_legs); // a reading's
/// ```
#[doc(inline)]
pub use tricept_model::effects::GenericSpec;
/// The quantities of an effect one plausible range judges.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, Judged, Measure};
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// let j: &Judged = &lead.plausible[0];
/// assert_eq!(j.of.len(), 3); // each leg's lead
/// assert_eq!(j.of[2].0, Measure::Parameter(2));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::Judged;
/// A quantity of an effect's fit judged against a plausible range, with
/// the label its messages use.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, Judgement, Measure};
/// let judged: Vec<Judgement> = EffectName::LegLead.judgements();
/// assert_eq!(judged.len(), 3); // each leg's lead
/// assert!(judged.iter().all(|j| j.range.unit == "ppm"));
/// assert_eq!(judged[1].measure, Measure::Parameter(1));
/// ```
#[doc(inline)]
pub use tricept_model::effects::Judgement;
/// How an effect enters the model: per leg, per reading, in the kinematics,
/// or row by row.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, Kind};
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// assert!(matches!(lead.kind, Kind::Leg(_)));
/// assert_eq!(lead.kind.label(), "leg");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::Kind;
/// A cause an effect is known to be confused with: which, why, and what
/// measurement tells them apart.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, KnownAlias};
/// let eccentricity = "encoder-eccentricity".parse::<EffectName>()?.spec();
/// let alias: &KnownAlias = &eccentricity.aliases[0];
/// assert_eq!(alias.with, "encoder-gain");
/// assert!(!alias.why.is_empty() && !alias.separate_by.is_empty());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::KnownAlias;
/// What a leg effect's columns are evaluated at: the nominal machine, the
/// leg commands (mm), the approach directions and the temperature.
///
/// # Example
/// ```
/// use tricept_ident::effects::{Basis, EffectName, Kind, LegContext};
/// use tricept_ident::kinematics::GeometricMachine;
/// let nominal = GeometricMachine::paper();
/// let at = LegContext { nominal: &nominal, commands_mm: [800.0, 900.0, 1000.0], approach: None, temperature_c: None };
/// let Kind::Leg(columns) = EffectName::LegLead.spec().kind else { unreachable!() };
/// let entries = columns(&at).map_err(|e| e.to_string())?;
/// // lead k of leg i: k ppm of its command, mm per ppm
/// assert_eq!(entries[2].1, Basis::Leg(2));
/// assert!((entries[2].2 - 1000.0e-6).abs() < 1e-15);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::LegContext;
/// A static leg effect's place in a machine file's leg effects.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, Deployment, LegDeployment};
/// use tricept_ident::kinematics::LegEffectsDescription;
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// let Deployment::LegEffects(d) = lead.deployment else { unreachable!() };
/// let d: LegDeployment = d;
/// let mut effects = LegEffectsDescription::default();
/// (d.set)(&mut effects, 1, 80.0);
/// assert_eq!(effects.lead_ppm, [0.0, 80.0, 0.0]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::LegDeployment;
/// Realistic values of an effect's parameters on a machine, with a label.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, Magnitude};
/// use tricept_ident::kinematics::GeometricMachine;
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// let m: Vec<Magnitude> = (lead.realistic)(&GeometricMachine::paper());
/// assert!(m.iter().all(|m| m.values.len() == lead.parameters.len()));
/// assert_eq!(m[0].label, "50 ppm");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::Magnitude;
/// A quantity of an effect's fitted parameters that a range judges: a
/// parameter, an amplitude, a peak-to-valley or a constant.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, Measure};
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// let judged: Vec<Measure> = lead.plausible[0].of.iter().map(|(m, _)| *m).collect();
/// assert_eq!(judged, [Measure::Parameter(0), Measure::Parameter(1), Measure::Parameter(2)]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::Measure;
/// What a campaign must log (and vary) for an effect to be seen.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, Needs};
/// let thermal = EffectName::ALL.iter().find(|n| n.spec().needs == Needs::Temperature);
/// assert!(thermal.is_some());
/// assert_eq!(Needs::Temperature.columns(), Some("temp_c"));
/// assert!(Needs::Temperature.follows_time() && !Needs::Nothing.follows_time());
/// assert_eq!(Needs::Nothing.advice(), None);
/// ```
#[doc(inline)]
pub use tricept_model::effects::Needs;
/// One parameter of an effect: its name (unit in it), unit and typical value.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, Parameter};
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// let p: &Parameter = &lead.parameters[1];
/// assert_eq!((p.name, p.unit), ("lead2_ppm", "ppm"));
/// assert!(p.name.ends_with(p.unit));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::Parameter;
/// A range of plausible values of one quantity of an effect, with its reason.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, PlausibleRange};
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// let r: PlausibleRange = lead.plausible[0].range;
/// assert_eq!((r.quantity, r.unit), ("lead_ppm", "ppm"));
/// assert!(r.min < 0.0 && 0.0 < r.max);
/// assert_eq!(r.to_range().max, r.max);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::PlausibleRange;
/// The axes of the residual plot that shows an effect.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, PlotAxes, XAxis, YAxis};
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// let plot: PlotAxes = lead.plot;
/// assert_eq!((plot.x, plot.y), (XAxis::LegCommand(0), YAxis::LegResidual(0)));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::PlotAxes;
/// What a [`Simulate`] hook may depend on at one pose of a simulated
/// campaign (commands in mm, the temperature change in K, the approach
/// direction of each leg).
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, PoseState};
/// use tricept_ident::kinematics::{GeometricMachine, Machine, Vector3};
/// // Backlash depends on the direction each leg approached from.
/// let backlash = (EffectName::Backlash.spec().simulation.typical)();
/// let ik = Machine::paper().inverse(&Vector3::new(0.0, 0.0, 750.0))?;
/// let extra = |approach: [i8; 3]| {
///     let state = PoseState {
///         commands_mm: ik.legs_mm, nominal_up: ik.up, delta_temp_k: 0.0, approach, fraction: 0.0,
///     };
///     let mut extra_mm = [0.0; 3];
///     backlash.extra_leg_length(&GeometricMachine::paper(), &state, &mut extra_mm);
///     extra_mm
/// };
/// assert_ne!(extra([1; 3]), extra([-1; 3]));
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::PoseState;
/// An effect's simulation hooks (what [`EffectSimulation`]'s `typical` and
/// `parse` return): each adds its part to a simulated campaign.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, PoseState, Simulate};
/// use tricept_ident::kinematics::{GeometricMachine, Machine, Vector3};
/// // A leg lead adds length in proportion to the commanded length.
/// let lead: Box<dyn Simulate> = (EffectName::LegLead.spec().simulation.typical)();
/// let ik = Machine::paper().inverse(&Vector3::new(0.0, 0.0, 750.0))?;
/// let at = |scale: f64| {
///     let commands_mm = ik.legs_mm.map(|q| q * scale);
///     let state = PoseState {
///         commands_mm, nominal_up: ik.up, delta_temp_k: 0.0, approach: [1; 3], fraction: 0.0,
///     };
///     let mut extra_mm = [0.0; 3];
///     lead.extra_leg_length(&GeometricMachine::paper(), &state, &mut extra_mm);
///     extra_mm
/// };
/// let (once, twice) = (at(1.0), at(2.0));
/// assert!(once.iter().any(|e| e.abs() > 1e-6));
/// for leg in 0..3 {
///     assert!((twice[leg] - 2.0 * once[leg]).abs() < 1e-12);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::Simulate;
/// What every [`Simulate`] type has from its `Clone` and `Serialize`
/// (implemented for all of them).
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, SimulateObject};
/// let lead = (EffectName::LegLead.spec().simulation.typical)();
/// let copy = lead.clone_box();
/// assert_eq!(format!("{copy:?}"), format!("{lead:?}"));
/// ```
#[doc(inline)]
pub use tricept_model::effects::SimulateObject;
/// What an effect's file says about its simulation: its `--truth-effect`
/// tag, the cause a perfect diagnosis would name, its input keys.
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, EffectSimulation};
/// let sim: &EffectSimulation = &EffectName::LegLead.spec().simulation;
/// assert_eq!((sim.tag, sim.cause), ("leg-lead", "leg-lead")); // in the vocabulary: itself
/// assert!(!sim.keys.is_empty());
/// ```
#[doc(inline)]
pub use tricept_model::effects::Simulation as EffectSimulation;
/// An alias that is structural: the common part of per-leg parameters
/// that a scaled machine also explains (a common leg lead and a scale
/// gain).
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, Structural};
/// let structural: Vec<Structural> = EffectName::ALL
///     .iter()
///     .flat_map(|e| e.spec().aliases)
///     .filter_map(|a| a.structural)
///     .collect();
/// assert!(!structural.is_empty());
/// for s in &structural { // the effect named declares its common part
///     assert!(s.common_of.parse::<EffectName>()?.spec().common_part.is_some());
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::effects::Structural;
/// The error of a name that is not an effect of the vocabulary (it lists
/// the known ones).
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, UnknownEffect};
/// let e: UnknownEffect = "leg-leed".parse::<EffectName>().unwrap_err();
/// assert_eq!(e.0, "leg-leed");
/// assert!(e.to_string().contains("unknown effect `leg-leed`") && e.to_string().contains("leg-lead"));
/// ```
#[doc(inline)]
pub use tricept_model::effects::UnknownEffect;
/// The x axis of a residual plot (with its label and unit).
///
/// # Example
/// ```
/// use tricept_ident::effects::XAxis;
/// assert_eq!(XAxis::LegCommand(0).label(), "leg 1 command (mm)");
/// assert_eq!(XAxis::Temperature.label(), "temperature (°C)");
/// ```
#[doc(inline)]
pub use tricept_model::effects::XAxis;
/// The y axis of a residual plot (with its label and unit).
///
/// # Example
/// ```
/// use tricept_ident::effects::YAxis;
/// assert_eq!(YAxis::LegResidual(2).label(), "leg 3 length residual (um)");
/// assert_eq!(YAxis::Reading(0).label(), "phi residual (arcsec)");
/// assert_eq!(YAxis::Reading(2).label(), "s residual (um)");
/// ```
#[doc(inline)]
pub use tricept_model::effects::YAxis;
/// A plausible range as the diagnosis' table holds it: does an estimate with
/// its standard deviation fit it?
///
/// # Example
/// ```
/// use tricept_ident::effects::{EffectName, Range};
/// let lead = "leg-lead".parse::<EffectName>()?.spec();
/// let r: Range = lead.plausible[0].range.to_range();
/// assert!(r.admits(50.0, 5.0)); // tens of ppm
/// assert!(!r.admits(r.max + 100.0, 1.0)); // 3 sigma away
/// assert!(!r.admits(f64::NAN, 1.0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_model::plausibility::Range;

/// An effect a simulated machine hides ([`EffectList::effects`], `simulate`'s truth).
///
/// # Example
/// ```
/// use tricept_ident::effects::{Effect, effects};
/// let list = effects(Some("leg-lead"))?;
/// let lead: &Effect = &list.effects()[0];
/// let mut request = tricept_ident::simulate::SimulateRequest::new();
/// request.truth_effects.push(lead.clone());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_plant::Effect;

/// The effects listed: all, or the one asked for.
///
/// # Example
/// ```
/// use tricept_ident::effects::effects;
/// let lead = effects(Some("leg-lead"))?;
/// assert_eq!(lead.effects().len(), 1);
/// assert_eq!(lead.exit_code(), tricept_ident::EXIT_OK);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct EffectList {
    effects: Vec<Effect>,
}

crate::outcome::outcome!(EffectList);

/// The simulator's effects, or the one named `name` (`leg-lead`,
/// `compliance`, ...): an input error naming the effects when there is no
/// such effect.
///
/// # Example
/// ```
/// let all = tricept_ident::effects::effects(None).unwrap();
/// assert!(all.report().contains("leg-lead"));
/// assert!(tricept_ident::effects::effects(Some("nothing")).is_err());
/// ```
pub fn effects(name: Option<&str>) -> Result<EffectList, Error> {
    let all = typical_effects();
    let Some(name) = name else {
        return Ok(EffectList { effects: all });
    };
    let found: Vec<Effect> = all.iter().filter(|e| e.tag() == name).cloned().collect();
    if found.is_empty() {
        return Err(Error::input(format!(
            "effects: no simulated effect `{}`; the effects are {}",
            name.chars().take(40).collect::<String>().escape_debug(),
            all.iter().map(Effect::tag).collect::<Vec<_>>().join(", ")
        )));
    }
    Ok(EffectList { effects: found })
}

impl EffectList {
    /// The effects, each at its typical magnitude.
    pub fn effects(&self) -> &[Effect] {
        &self.effects
    }

    /// Always 0: a listing has no verdict.
    pub fn exit_code(&self) -> u8 {
        EXIT_OK
    }

    /// Always `None`: a listing has no verdict.
    pub fn reason(&self) -> Option<&str> {
        None
    }

    /// An array of one JSON object per effect (`tricept effects --json`
    /// prints one per line), each with `format_version` first: `effect`,
    /// `in_vocabulary`, `diagnosed_as`, `keys` (`key`, `unit`, `meaning`)
    /// and `example`.
    pub fn to_json(&self) -> Value {
        let mut out = Vec::new();
        for e in &self.effects {
            let keys: Vec<Value> = e
                .keys()
                .iter()
                .map(|k| json!({"key": k.key, "unit": k.unit, "meaning": k.meaning}))
                .collect();
            let line = json!({
                "effect": e.tag(),
                "in_vocabulary": e.in_vocabulary(),
                "diagnosed_as": e.name().to_string(),
                "keys": keys,
                "example": serde_json::to_value(e).unwrap_or(Value::Null),
            });
            out.push(crate::outcome::versioned(line));
        }
        Value::Array(out)
    }

    /// The listing as text (what `tricept effects` prints): each effect,
    /// its keys with units and meanings, and its typical `--truth-effect`.
    pub fn report(&self) -> String {
        let mut out = String::new();
        for e in &self.effects {
            let example = serde_json::to_string(e).unwrap_or_default();
            let named = if e.in_vocabulary() {
                "in the diagnosis' vocabulary".to_string()
            } else {
                format!("outside the vocabulary: described as `{}`", e.name())
            };
            out.push_str(&format!("{} ({named})\n", e.tag()));
            let width = e.keys().iter().map(|k| k.key.len()).max().unwrap_or(0);
            for k in e.keys() {
                out.push_str(&format!(
                    "  {:<width$}  {:<12} {}\n",
                    k.key, k.unit, k.meaning
                ));
            }
            out.push_str(&format!("  typical: '{example}'\n\n"));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_effect_is_one_json_line_and_an_unknown_one_is_an_input_error() {
        let one = effects(Some("leg-lead")).unwrap();
        let json = one.to_json();
        assert_eq!(json.as_array().map(Vec::len), Some(1));
        let v = &json[0];
        assert_eq!(v["effect"], "leg-lead");
        assert_eq!(v["format_version"], 1);
        assert!(one.report().starts_with("leg-lead ("));
        let all = effects(None).unwrap();
        assert!(all.effects().len() > 1);
        assert_eq!(
            all.to_json().as_array().map(Vec::len),
            Some(all.effects().len())
        );
        let e = effects(Some("nothing")).unwrap_err();
        assert_eq!(e.exit_code(), crate::EXIT_INPUT);
        assert!(e.message().contains("leg-lead"), "{}", e.message());
    }
}
