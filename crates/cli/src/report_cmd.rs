//! `tricept report`: one self-contained HTML page per calibrated machine
//! (`tricept_ident::report`): flags to a `ReportRequest`, one door call,
//! the verdict printed.

use std::path::PathBuf;

use clap::Args;
use tricept_ident::report::{ReportRequest, report};

use crate::cli_error::CliError;

/// `tricept report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// The calibrated machine file (`identify --write-machine`,
    /// `diagnose --write-machine`).
    #[arg(long, value_name = "CAL.json")]
    pub machine: PathBuf,
    /// The campaign the calibration was made from (its SHA-256 must be the
    /// record's): residuals, what was looked for, each term's gain.
    #[arg(long, value_name = "CAMPAIGN.csv")]
    pub data: Option<PathBuf>,
    /// The check history of this calibration (`check --history`).
    #[arg(long, value_name = "CHECKS.jsonl")]
    pub history: Option<PathBuf>,
    /// The folder `tricept export --out` wrote for this calibration.
    #[arg(long, value_name = "DIR")]
    pub export: Option<PathBuf>,
    /// The page to write (HTML, self-contained; prints to A4).
    #[arg(long, value_name = "PAGE.html")]
    pub out: PathBuf,
    /// Print the verdict as JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `tricept report`.
pub fn run(a: &ReportArgs) -> Result<u8, CliError> {
    let mut request = ReportRequest::new(a.machine.as_path(), a.out.clone());
    request.data = a.data.clone();
    request.history = a.history.clone();
    request.export = a.export.clone();
    let r = report(request)?;
    if a.json {
        crate::output::write_json(r.to_json());
    } else {
        crate::output::write_text(&r.report());
    }
    Ok(r.exit_code())
}
