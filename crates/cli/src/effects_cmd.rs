//! `tricept effects [EFFECT]`: every effect the simulator can hide in a
//! machine (`simulate --truth-effect`), with its keys, their units and a
//! typical example ([`tricept_plant::catalogue`]), and whether the
//! diagnosis names it (in its vocabulary) or describes it through a generic
//! family.

use clap::Args;
use serde_json::{Value, json};
use tricept_plant::Effect;
use tricept_plant::catalogue::typical_effects;

use crate::cli_error::CliError;

/// Arguments of `tricept effects`.
#[derive(Debug, Args)]
pub struct EffectsArgs {
    /// One effect (`leg-lead`, `compliance`, ...); without it, all.
    #[arg(value_name = "EFFECT")]
    effect: Option<String>,
    /// One JSON object per line: `effect`, `in_vocabulary`, `diagnosed_as`,
    /// `keys` (`key`, `unit`, `meaning`) and `example` (what
    /// `--truth-effect` takes).
    #[arg(long)]
    json: bool,
}

/// Runs `tricept effects`.
pub fn run(a: &EffectsArgs) -> Result<u8, CliError> {
    let all = typical_effects();
    let chosen: Vec<&Effect> = match &a.effect {
        None => all.iter().collect(),
        Some(name) => {
            let found: Vec<&Effect> = all.iter().filter(|e| e.tag() == name).collect();
            if found.is_empty() {
                return Err(CliError::input(format!(
                    "effects: no simulated effect `{}`; the effects are {}",
                    name.chars().take(40).collect::<String>().escape_debug(),
                    all.iter().map(Effect::tag).collect::<Vec<_>>().join(", ")
                )));
            }
            found
        }
    };
    for e in chosen {
        let example = serde_json::to_string(e).map_err(|x| CliError::other(x.to_string()))?;
        if a.json {
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
                "example": serde_json::from_str::<Value>(&example)
                    .map_err(|x| CliError::other(x.to_string()))?,
            });
            outln!("{line}");
        } else {
            let named = if e.in_vocabulary() {
                "in the diagnosis' vocabulary".to_string()
            } else {
                format!("outside the vocabulary: described as `{}`", e.name())
            };
            outln!("{} ({named})", e.tag());
            let width = e.keys().iter().map(|k| k.key.len()).max().unwrap_or(0);
            for k in e.keys() {
                outln!("  {:<width$}  {:<12} {}", k.key, k.unit, k.meaning);
            }
            outln!("  typical: --truth-effect '{example}'");
            outln!("");
        }
    }
    Ok(0)
}
