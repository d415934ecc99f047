//! `tricept check`: has the machine changed since its calibration? A short
//! check campaign tested against the calibrated machine file
//! (`tricept_check`), with an optional history and its trend plots.

use std::path::{Path, PathBuf};

use clap::Args;
use serde_json::{Value, json};
use tricept_check::history::{Entry, Trend, append, trends};
use tricept_check::{CheckError, CheckOptions, CheckReport, Reference, check};

use crate::args::{MachineArgs, NoiseArgs, load_with_noise, read_data};
use crate::cli_error::{CliError, EXIT_INADEQUATE};

/// `tricept check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The check campaign's measured data (CSV as for `identify`; with
    /// `temp_c` the legs' thermal state is checked too).
    #[arg(long, value_name = "FILE.csv")]
    pub data: PathBuf,
    /// Family-wise false-alarm probability of the verdict.
    #[arg(long, default_value_t = tricept_check::DEFAULT_ALPHA, value_name = "P")]
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

fn check_error(e: CheckError) -> CliError {
    match e {
        CheckError::Record(_)
        | CheckError::Blind(_)
        | CheckError::Invalid(_)
        | CheckError::HistoryLine(_) => CliError::input(e.to_string()),
        CheckError::Kinematics { .. } => CliError::input(e.to_string()),
        _ => CliError::other(e.to_string()),
    }
}

/// `tricept check`.
pub fn run(a: &CheckArgs) -> Result<u8, CliError> {
    let Some(machine_path) = &a.machine.machine else {
        return Err(CliError::input(
            "check: --machine CALIBRATED.json is needed: a check compares the machine with its calibration (a machine file written by `tricept identify --write-machine`)",
        ));
    };
    let loaded = load_with_noise(&a.machine, &a.noise)?;
    let reference = Reference::from_description(loaded.description())
        .map_err(|e| CliError::input(format!("{}: {}", machine_path.display(), e)))?;
    let data = read_data(&a.data, loaded.machine())?;
    if !(a.alpha > 0.0 && a.alpha < 0.5) {
        return Err(CliError::input(format!(
            "--alpha: the false-alarm probability must lie between 0 and 0.5, got {}",
            a.alpha
        )));
    }
    if let Some(h) = &a.history {
        // A history that cannot be read is refused before the check runs.
        tricept_check::history::read(h).map_err(check_error)?;
    }
    let mut options = CheckOptions::for_machine(loaded.machine());
    options.alpha = a.alpha;
    let report = check(&reference, &data, &options).map_err(|e| match e {
        CheckError::Blind(_) => CliError::input(format!("{}: {e}", a.data.display())),
        e => check_error(e),
    })?;
    if report.is_blind() {
        return Err(CliError::input(format!(
            "{}: the check's poses cannot see a change: no leg or joint change of less than 1 mm would be detected ({} poses); plan them with `tricept plan --instrument check`",
            a.data.display(),
            report.poses
        )));
    }
    let history = match &a.history {
        Some(path) => {
            let time = tricept_ident::machine_file::utc_now();
            let unix_s = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0.0, |d| d.as_secs_f64());
            let entry = Entry::of(
                &report,
                &time,
                unix_s,
                &machine_path.display().to_string(),
                &a.data.display().to_string(),
            );
            let entries = append(path, &entry).map_err(check_error)?;
            let t = trends(&entries);
            if let Some(dir) = &a.plot {
                plot_trends(dir, &t)?;
            }
            Some((path.clone(), entries.len(), t))
        }
        None => None,
    };
    if a.machine.json {
        let mut v = serde_json::to_value(&report).unwrap_or(Value::Null);
        if let Value::Object(o) = &mut v {
            o.insert("machine".into(), machine_path.display().to_string().into());
            o.insert("data_file".into(), a.data.display().to_string().into());
            if let Some((path, n, t)) = &history {
                o.insert(
                    "history".into(),
                    json!({"file": path.display().to_string(), "checks": n, "trends": t}),
                );
            }
        }
        outln!("{v}");
    } else {
        outln!(
            "check of {} against `{}` ({})",
            a.data.display(),
            reference.name(),
            machine_path.display()
        );
        crate::output::write_text(&report.to_text());
        if let Some((path, n, t)) = &history {
            outln!("history {} ({n} checks):", path.display());
            for trend in t {
                outln!("  {}", trend_text(trend));
            }
        }
    }
    Ok(exit_code(&report, a.data.as_path()))
}

/// 0 unchanged, 3 changed (one line on stderr saying what).
fn exit_code(report: &CheckReport, data: &Path) -> u8 {
    if !report.changed {
        return 0;
    }
    let what = match report.most_likely {
        Some(i) if report.shortlist.len() > 1 => format!(
            "most likely {} (cannot be told apart from {})",
            report.candidates[i].name,
            report.shortlist[1..].join(", ")
        ),
        Some(i) => format!("most likely {}", report.candidates[i].name),
        None => "cause unknown".to_string(),
    };
    errln!(
        "check: exit {EXIT_INADEQUATE}: the machine changed since its calibration ({}): {what}",
        data.display()
    );
    EXIT_INADEQUATE
}

/// One line of a trend: the last value against its band, the slope.
fn trend_text(t: &Trend) -> String {
    let last = t.values.len().saturating_sub(1);
    let value = t.values.get(last).copied().unwrap_or(f64::NAN);
    let band = t.band.get(last).copied().unwrap_or(f64::NAN);
    let slope = match t.slope_per_day {
        Some((s, sd)) => format!("; slope {s:+.2} +- {sd:.2} {}/day", t.unit),
        None => String::new(),
    };
    let outside = if t.outside.is_empty() {
        "inside its band at every check".to_string()
    } else {
        format!(
            "OUTSIDE its band at check(s) {}",
            t.outside
                .iter()
                .map(|i| (i + 1).to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    format!(
        "{}: last {value:+.2} {} (band +-{band:.2}){slope}; {outside}",
        t.name, t.unit
    )
}

/// One SVG per key quantity: the estimates with 2-sd bands and the band
/// beyond which a check flags it, against the check's number.
fn plot_trends(dir: &Path, trends: &[Trend]) -> Result<(), CliError> {
    crate::files::create_dir(dir)?;
    for t in trends {
        let path = dir.join(format!("check-{}.svg", t.name));
        let x: Vec<f64> = (1..=t.values.len()).map(|i| i as f64).collect();
        let title = format!("{} over the checks ({})", t.name, t.unit);
        let y_label = format!("{} ({})", t.name, t.unit);
        let drawn = tricept_plot::curves(
            &path,
            &tricept_plot::Axes {
                title: &title,
                x_label: "check",
                y_label: &y_label,
                log_x: false,
                log_y: false,
            },
            &[
                tricept_plot::Curve {
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
                tricept_plot::Curve {
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
