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
pub use tricept_model::effects::Simulation as EffectSimulation;
pub use tricept_model::effects::{
    Basis, CheckColumns, CheckWhen, GenericSpec, LegContext, LegDeployment, PoseState,
    SimulateObject, Structural, UnknownEffect, XAxis, YAxis,
};
pub use tricept_model::effects::{CauseName, EffectKey, EffectSpec, Judgement};
pub use tricept_model::effects::{
    CheckRole, CommonPart, Deployment, GenericFamily, Judged, Kind, KnownAlias, Magnitude, Measure,
    Needs, Parameter, PlausibleRange, PlotAxes, Simulate,
};
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
