//! `tricept effects [EFFECT]`: every effect the simulator can hide in a
//! machine (`simulate --truth-effect`), with its keys, their units and a
//! typical example, and whether the diagnosis names it; the listing is the
//! door's (`tricept_ident::effects`).

use clap::Args;

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
    let list = tricept_ident::effects::effects(a.effect.as_deref())?;
    if a.json {
        crate::output::write_json_lines(&list.to_json());
    } else {
        crate::output::write_text(&list.report());
    }
    Ok(list.exit_code())
}
