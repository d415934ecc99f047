//! `tricept check`: has the machine changed since its calibration? The
//! flags into a request of the door (`tricept_ident::check`), the report
//! printed, the history's trends drawn.

use std::path::{Path, PathBuf};

use clap::Args;
use tricept_ident::check::{CheckRequest, Trend, check};

use crate::args::{MachineArgs, NoiseArgs, load_with_noise};
use crate::cli_error::CliError;

/// `tricept check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The check campaign's measured data (CSV as for `identify`; with
    /// `temp_c` the legs' thermal state is checked too).
    #[arg(long, value_name = "FILE.csv")]
    pub data: PathBuf,
    /// Family-wise false-alarm probability of the verdict.
    #[arg(long, default_value_t = tricept_ident::check::DEFAULT_ALPHA, value_name = "P")]
    pub alpha: f64,
    /// Append the check to this history (JSON lines: time, verdict, the
    /// changes and their sizes) and report the trends of its key
    /// quantities.
    #[arg(long, value_name = "FILE.jsonl")]
    pub history: Option<PathBuf>,
    /// Draw the history's trends with their bands as SVG into this
    /// directory (needs --history).
    #[arg(long, value_name = "DIR", requires = "history")]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept check`.
pub fn run(a: &CheckArgs) -> Result<u8, CliError> {
    if a.machine.machine.is_none() {
        return Err(CliError::input(
            "check: --machine CALIBRATED.json is needed: a check compares the machine with its calibration (a machine file written by `tricept identify --write-machine`)",
        ));
    }
    let mut request = CheckRequest::new(load_with_noise(&a.machine, &a.noise)?, a.data.as_path());
    request.alpha = a.alpha;
    request.history = a.history.clone();
    let result = check(request)?;
    if let Some(dir) = &a.plot {
        plot_trends(dir, result.trends())?;
    }
    if a.machine.json {
        crate::output::write_json(result.to_json());
    } else {
        crate::output::write_text(&result.report());
    }
    for w in result.warnings() {
        errln!("check: warning: {w}");
    }
    if let Some(why) = result.reason() {
        errln!("check: exit {}: {why}", result.exit_code());
    }
    Ok(result.exit_code())
}

/// One SVG per key quantity: the estimates with 2-sd bands and the band
/// beyond which a check flags it, against the check's number.
fn plot_trends(dir: &Path, trends: &[Trend]) -> Result<(), CliError> {
    crate::files::create_dir(dir)?;
    for t in trends {
        let path = crate::files::output_in("--plot", dir, &format!("check-{}.svg", t.name))?;
        let x: Vec<f64> = (1..=t.values.len()).map(|i| i as f64).collect();
        let title = format!("{} over the checks ({})", t.name, t.unit);
        let y_label = format!("{} ({})", t.name, t.unit);
        let drawn = tricept_ident::advanced::plot::curves(
            &path,
            &tricept_ident::advanced::plot::Axes {
                title: &title,
                x_label: "check",
                y_label: &y_label,
                log_x: false,
                log_y: false,
            },
            &[
                tricept_ident::advanced::plot::Curve {
                    name: "estimate +- 2 sd".into(),
                    x: x.clone(),
                    y: t.values.clone(),
                    band: Some(
                        t.values
                            .iter()
                            .zip(&t.std_dev)
                            .map(|(v, s)| (v - 2.0 * s, v + 2.0 * s))
                            .collect(),
                    ),
                },
                tricept_ident::advanced::plot::Curve {
                    name: "a check flags beyond".into(),
                    x,
                    y: vec![0.0; t.days.len()],
                    band: Some(t.band.iter().map(|b| (-b, *b)).collect()),
                },
            ],
            &[],
            &[],
        );
        crate::files::plotted(&path, drawn)?;
    }
    Ok(())
}
