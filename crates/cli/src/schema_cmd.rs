//! `tricept schema [NAME]`: the JSON Schema (Draft 2020-12) of a file
//! tricept writes or of a verb's `--json` output, embedded in the binary
//! from `docs/schema/` (where the repository keeps them beside the docs);
//! without a name, the list. The CLI's tests validate real outputs
//! against every schema (`crates/cli/tests/cli/schema/`), so a schema
//! cannot drift from what the verbs print.

use clap::Args;

use crate::cli_error::CliError;

/// Arguments of `tricept schema`.
#[derive(Debug, Args)]
pub struct SchemaArgs {
    /// The file or output: `machine`, `identify`, `diagnose`, `check`,
    /// `export`, `fleet`, `report`, ... (`tricept schema` lists them all).
    #[arg(value_name = "NAME")]
    name: Option<String>,
}

/// Every schema: name, what it describes, text (JSON Schema).
pub const SCHEMAS: [(&str, &str, &str); 19] = [
    (
        "machine",
        "a machine file (nominal or calibrated: identify, diagnose --write-machine; `tricept machine --json`)",
        include_str!("../../../docs/schema/machine.json"),
    ),
    (
        "prior",
        "a batch's prior file (`tricept fleet --write-prior`)",
        include_str!("../../../docs/schema/prior.json"),
    ),
    (
        "check-history",
        "one line of a check history (`tricept check --history FILE.jsonl`)",
        include_str!("../../../docs/schema/check-history.json"),
    ),
    (
        "export-summary",
        "an export's summary file (`tricept export --out DIR`: DIR/export.json)",
        include_str!("../../../docs/schema/export-summary.json"),
    ),
    (
        "ik",
        "`tricept ik --json`",
        include_str!("../../../docs/schema/ik.json"),
    ),
    (
        "fk",
        "`tricept fk --json`",
        include_str!("../../../docs/schema/fk.json"),
    ),
    (
        "tool-ik",
        "`tricept tool-ik --json`",
        include_str!("../../../docs/schema/tool-ik.json"),
    ),
    (
        "identifiability",
        "`tricept identifiability --json`",
        include_str!("../../../docs/schema/identifiability.json"),
    ),
    (
        "identify",
        "`tricept identify --json` (one campaign, several, a prior, or fused with external measurements)",
        include_str!("../../../docs/schema/identify.json"),
    ),
    (
        "simulate",
        "`tricept simulate --out FILE --json`",
        include_str!("../../../docs/schema/simulate.json"),
    ),
    (
        "diagnose",
        "`tricept diagnose --json`",
        include_str!("../../../docs/schema/diagnose.json"),
    ),
    (
        "detectability",
        "`tricept detectability --json`",
        include_str!("../../../docs/schema/detectability.json"),
    ),
    (
        "compensate",
        "`tricept compensate --json`",
        include_str!("../../../docs/schema/compensate.json"),
    ),
    (
        "check",
        "`tricept check --json`",
        include_str!("../../../docs/schema/check.json"),
    ),
    (
        "plan",
        "`tricept plan --json`",
        include_str!("../../../docs/schema/plan.json"),
    ),
    (
        "effects",
        "one line of `tricept effects --json`",
        include_str!("../../../docs/schema/effects.json"),
    ),
    (
        "fleet",
        "`tricept fleet --json`",
        include_str!("../../../docs/schema/fleet.json"),
    ),
    (
        "export",
        "`tricept export --json`",
        include_str!("../../../docs/schema/export.json"),
    ),
    (
        "report",
        "`tricept report --json`",
        include_str!("../../../docs/schema/report.json"),
    ),
];

/// Runs `tricept schema`.
pub fn run(a: &SchemaArgs) -> Result<u8, CliError> {
    let Some(name) = &a.name else {
        outln!(
            "JSON Schemas (Draft 2020-12; tricept schema NAME; docs/schema/NAME.json in the source repository):"
        );
        for (name, what, _) in SCHEMAS {
            outln!("  {name:<16} {what}");
        }
        return Ok(0);
    };
    let name = name
        .trim_start_matches("docs/schema/")
        .trim_end_matches(".json");
    match SCHEMAS.iter().find(|(n, _, _)| *n == name) {
        Some((_, _, text)) => {
            crate::output::write_text(text);
            Ok(0)
        }
        None => Err(CliError::input(format!(
            "schema: no schema `{name}`; the schemas are {}",
            SCHEMAS.map(|s| s.0).join(", ")
        ))),
    }
}
