//! `tricept docs [PAGE]`: the repository's documentation pages, embedded in
//! the binary, so that an installed `tricept` (far from the source tree)
//! still has the pages its help texts name (`docs/data-format.md` and the
//! others; `tricept docs docs/data-format.md` works too).

use clap::Args;

use crate::cli_error::CliError;

/// Arguments of `tricept docs`.
#[derive(Debug, Args)]
pub struct DocsArgs {
    /// The page: `data-format`, `diagnosis`, `hybrid`, ... or its path in
    /// the repository (`docs/data-format.md`); without it, the list.
    #[arg(value_name = "PAGE")]
    page: Option<String>,
}

/// Every page: name, what it holds, text (Markdown).
const PAGES: [(&str, &str, &str); 14] = [
    (
        "data-format",
        "the measured-data CSV, the external measurements, the machine JSON, every output file (columns, keys, units)",
        include_str!("../../../docs/data-format.md"),
    ),
    (
        "conventions",
        "units, frames and the choices the paper leaves open",
        include_str!("../../../docs/conventions.md"),
    ),
    (
        "identifiability",
        "what the UP limb's sensors can and cannot identify, and why",
        include_str!("../../../docs/identifiability.md"),
    ),
    (
        "diagnosis",
        "`tricept diagnose`: the method, the effects and their units, the generic dictionary, plausibility",
        include_str!("../../../docs/diagnosis.md"),
    ),
    (
        "hybrid",
        "external measurements (tracker, ballbar, touch-offs) fused with the self-calibration; `tricept plan`",
        include_str!("../../../docs/hybrid.md"),
    ),
    (
        "check",
        "`tricept check`: has the machine changed since its calibration? The test, the candidates, planning a check, measured rates",
        include_str!("../../../docs/check.md"),
    ),
    (
        "report",
        "`tricept report`: one page per machine: its sections and sources, the verdict's rule, how histories and exports name their calibration",
        include_str!("../../../docs/report.md"),
    ),
    (
        "controllers",
        "`tricept export`: the compensation files of Sinumerik, Fanuc and Heidenhain controls, signs, units, limits, format errors",
        include_str!("../../../docs/controllers.md"),
    ),
    (
        "fleet",
        "pooled calibration: several campaigns of a machine, a batch of machines (the hierarchical model, its tests), a new machine from the batch's prior, the sparse solvers",
        include_str!("../../../docs/fleet.md"),
    ),
    (
        "reliability",
        "bad-input handling, robust estimation, fuzzing",
        include_str!("../../../docs/reliability.md"),
    ),
    (
        "testing",
        "how the tests are laid out, mutation testing of the decision code (`cargo xtask mutants`), measured counts",
        include_str!("../../../docs/testing.md"),
    ),
    (
        "python",
        "the `tricept` Python package: install, API, what it shares with the CLI, the example",
        include_str!("../../../docs/python.md"),
    ),
    (
        "reproduction",
        "the paper's Figs. 3 and 4 reproduced, and where they differ",
        include_str!("../../../docs/reproduction.md"),
    ),
    (
        "performance",
        "measured speed and memory, build times",
        include_str!("../../../docs/performance.md"),
    ),
];

/// Runs `tricept docs`.
pub fn run(a: &DocsArgs) -> Result<u8, CliError> {
    let Some(page) = &a.page else {
        outln!("Documentation pages (tricept docs PAGE; docs/PAGE.md in the source repository):");
        for (name, what, _) in PAGES {
            outln!("  {name:<16} {what}");
        }
        return Ok(0);
    };
    let name = page.trim_start_matches("docs/").trim_end_matches(".md");
    match PAGES.iter().find(|(n, _, _)| *n == name) {
        Some((_, _, text)) => {
            crate::output::write_text(text);
            Ok(0)
        }
        None => Err(CliError::input(format!(
            "docs: no page `{page}`; the pages are {}",
            PAGES.map(|p| p.0).join(", ")
        ))),
    }
}
