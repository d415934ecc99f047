//! `tricept diagnose` and `tricept detectability`: flags into a request
//! of the door (`tricept_ident::diagnosis`, `tricept_ident::detectability`),
//! the result printed, the residual plots drawn.

use std::path::{Path, PathBuf};

use clap::Args;
use tricept_ident::LoadedMachine;
use tricept_ident::advanced::Poses;
use tricept_ident::detectability::{DetectabilityRequest, detectability};
use tricept_ident::diagnosis::{
    DeployRule, DiagnoseRequest, DiagnoseResult, ResidualPlot, diagnose,
};
use tricept_ident::{DataInput, WriteOptions};

use crate::args::{MachineArgs, NoiseArgs, load_with_noise, read_data};
use crate::cli_error::CliError;

pub use tricept_ident::diagnosis::vocabulary_help;

/// `tricept diagnose`.
#[derive(Debug, Args)]
pub struct DiagnoseArgs {
    /// Measured-data CSV (context columns temp_c, time_s, dir1..3 are used when present).
    #[arg(long, value_name = "FILE.csv")]
    pub data: PathBuf,
    /// Write residual plots (SVG) of the named causes into this directory.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Estimate the sensor noise from repeated poses (the same commands
    /// logged on separate visits, at least 10 degrees of freedom) and test
    /// against it (F tests) instead of the stated noise.
    #[arg(long)]
    pub noise_from_data: bool,
    /// Standard deviation of the logged temperature, K (default 0.02): its
    /// noise enters the final adequacy test of temperature terms.
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    pub temperature_noise: Option<f64>,
    /// Override physical ranges of the plausibility table: a JSON object
    /// such as `{"thermal.expansion_ppm_per_k": [20, 26]}` (aluminium legs).
    #[arg(long, value_name = "FILE.json")]
    pub plausibility: Option<PathBuf>,
    /// Search the effects of the vocabulary only, not the generic
    /// dictionary (for comparison; effects outside the vocabulary are then
    /// reported as unexplained).
    #[arg(long)]
    pub no_dictionary: bool,
    /// Write the calibrated machine of the final model: the geometry
    /// de-biased by every deployed cause, each named effect where it goes
    /// (the list below: the static leg effects applied by ik, fk, tool-ik
    /// and compensate, the UP limb's class-2 errors in its description, the
    /// dynamic effects as controller parameters), the generic leg errors
    /// that are functions of the leg command as per-leg compensation
    /// tables (leg_effects.tables, applied by ik, fk, tool-ik and
    /// compensate), sensor corrections and time terms recorded only, and a
    /// `calibration` record saying what it applies and what it records.
    /// A cause is deployed only when the file with it is predicted better
    /// than without it, out of sample and where the sensors cannot see.
    /// Refused when the data are not explained (exit 3).
    #[arg(long, value_name = "FILE.json")]
    pub write_machine: Option<PathBuf>,
    /// Write the machine even when the data are not explained; the file
    /// says so.
    #[arg(long, requires = "write_machine")]
    pub force: bool,
    /// How a term is judged worth deploying: `expected-error` (the
    /// default: the file the report expects to be best, a term whose file
    /// has the smaller expected error by a move of at least 1 sd) or
    /// `confident` (only a move beyond 2 sd where the sensors cannot see:
    /// fewer files gain; docs/diagnosis.md, "Two rules").
    #[arg(long, value_name = "RULE", default_value = "expected-error", value_parser = deploy_rule)]
    pub deploy_rule: DeployRule,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept detectability`.
#[derive(Debug, Args)]
pub struct DetectabilityArgs {
    /// Pose set (as for `identifiability`; positions in mm).
    #[arg(long, default_value = "grid", conflicts_with = "data", value_parser = clap::value_parser!(Poses))]
    pub poses: Poses,
    /// Assess a logged campaign instead: its commands and their logged
    /// context (temperatures, times, approach directions) from this
    /// measured-data file; its readings are not used.
    #[arg(long, value_name = "FILE.csv")]
    pub data: Option<PathBuf>,
    /// Visit every pose twice, approaching from both directions.
    #[arg(long)]
    pub both_directions: bool,
    /// Temperature change over the campaign, K (0: no thermal signature;
    /// negative: cooling).
    #[arg(long, default_value_t = 2.0, value_name = "K")]
    pub temperature_drift: f64,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `--deploy-rule` as a deploy rule.
fn deploy_rule(name: &str) -> Result<DeployRule, CliError> {
    name.parse().map_err(CliError::input)
}

/// `tricept diagnose`.
pub fn run_diagnose(a: &DiagnoseArgs) -> Result<u8, CliError> {
    let loaded = load_with_noise(&a.machine, &a.noise)?;
    let data = read_with_progress(&a.data, &loaded)?;
    let mut request = DiagnoseRequest::new(data).machine(loaded);
    request.noise_from_data = a.noise_from_data;
    request.temperature_noise_k = a.temperature_noise;
    request.plausibility = a.plausibility.clone();
    request.dictionary = !a.no_dictionary;
    request.deploy_rule = a.deploy_rule;
    let result = diagnose(request)?;
    if let Some(dir) = &a.plots {
        plot_residuals(dir, result.plots())?;
    }
    let written = a
        .write_machine
        .as_ref()
        .map(|path| write_machine(&result, path, a.force));
    if a.machine.json {
        crate::output::write_json(result.to_json());
    } else {
        crate::output::write_text(&result.report());
    }
    if let Some(Err(e)) = written {
        return Err(e);
    }
    if let Some(why) = result.reason() {
        errln!("diagnose: exit {}: {why}", result.exit_code());
    }
    Ok(result.exit_code())
}

/// The data file read with a progress bar (large files on a terminal).
fn read_with_progress(path: &Path, loaded: &LoadedMachine) -> Result<DataInput, CliError> {
    Ok(DataInput::Read {
        file: path.to_path_buf(),
        data: read_data(path, loaded.geometry())?,
    })
}

/// Writes the extended machine, naming the file (and a forced write's
/// warning) on stderr.
fn write_machine(result: &DiagnoseResult, path: &Path, force: bool) -> Result<(), CliError> {
    let written = result.write_machine(path, WriteOptions::default().force(force))?;
    if let Some(why) = written.forced() {
        errln!(
            "warning: {}: written with --force although {why}",
            path.display()
        );
    }
    errln!("wrote {}", path.display());
    Ok(())
}

/// One SVG per named cause: its residuals before and after.
fn plot_residuals(dir: &Path, plots: &[ResidualPlot]) -> Result<(), CliError> {
    crate::files::create_dir(dir)?;
    for p in plots {
        let path = crate::files::output_in("--plots", dir, &format!("residual-{}.svg", p.effect))?;
        let drawn = tricept_ident::advanced::plot::scatter(
            &path,
            &tricept_ident::advanced::plot::Axes {
                title: &format!("{}: {}, before and after", p.effect, p.y_label),
                x_label: &p.x_label,
                y_label: &p.y_label,
                log_x: false,
                log_y: false,
            },
            &[
                ("geometric model".to_string(), p.before.clone()),
                (format!("with {}", p.effect), p.after.clone()),
            ],
        );
        crate::files::plotted(&path, drawn)?;
    }
    Ok(())
}

/// `tricept detectability`.
pub fn run_detectability(a: &DetectabilityArgs) -> Result<u8, CliError> {
    let loaded = load_with_noise(&a.machine, &a.noise)?;
    let data = match &a.data {
        Some(path) => Some(read_with_progress(path, &loaded)?),
        None => None,
    };
    let mut request = DetectabilityRequest::new(a.poses.clone()).machine(loaded);
    request.data = data;
    request.both_directions = a.both_directions;
    request.temperature_drift_k = a.temperature_drift;
    let report = detectability(request)?;
    if a.machine.json {
        crate::output::write_json(report.to_json());
    } else {
        crate::output::write_text(&report.report());
    }
    Ok(report.exit_code())
}
