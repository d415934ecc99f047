//! `cargo xtask report-sample`: the sample page of docs/report.md,
//! `docs/report-sample.html`, for the Table 2 fixture: the door's
//! `report` of its calibration (`fixtures/report/table2.json`) with its
//! campaign, a history of five daily checks (`fixtures/report/checks.jsonl`,
//! the last after leg 2 slipped by 25 um) and its SINUMERIK export
//! (`fixtures/report/export/`). The page is deterministic: rerunning this
//! gives the same bytes (`crates/report/tests/sample.rs` checks it in CI).
//!
//! `--inputs` makes the inputs first, as a user would with the CLI: the
//! calibration (`identify --write-machine`, dated now), five check
//! campaigns simulated from the Table 2 machine (20 random poses each;
//! their truth is in their comment lines), each checked and appended to
//! the history at 06:30 UTC on the five days after the calibration (the
//! sample's clock: the door's check stamps the time it runs), and the
//! export.

use std::path::{Path, PathBuf};

use clap::Args;
use tricept_ident::advanced::{ParameterSet, Poses, TrueErrors};
use tricept_ident::calibrate::{CalibrateRequest, calibrate};
use tricept_ident::check::{CheckRequest, check};
use tricept_ident::export::{ControlModel, ExportOptions, ExportRequest, export};
use tricept_ident::kinematics::MachineDescription;
use tricept_ident::report::{ReportRequest, report};
use tricept_ident::simulate::{SimulateRequest, simulate};

/// The sample's files, relative to the workspace (the page names them).
pub const MACHINE: &str = "fixtures/report/table2.json";
/// The calibration's campaign.
pub const DATA: &str = "fixtures/data/table2-grid-seed1.csv";
/// The check history.
pub const HISTORY: &str = "fixtures/report/checks.jsonl";
/// The export folder.
pub const EXPORT: &str = "fixtures/report/export";
/// The page.
pub const PAGE: &str = "docs/report-sample.html";

/// `cargo xtask report-sample`.
#[derive(Debug, Args)]
pub struct ReportSampleArgs {
    /// Make the inputs first (a new calibration, its checks and its
    /// export, dated now).
    #[arg(long)]
    inputs: bool,
}

type Failure = Box<dyn std::error::Error>;

/// Runs from the workspace's root, so that the page names its files as
/// the docs do.
pub fn run(args: ReportSampleArgs) -> Result<(), String> {
    sample(args).map_err(|e| e.to_string())
}

fn sample(args: ReportSampleArgs) -> Result<(), Failure> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    std::env::set_current_dir(&root)?;
    if args.inputs {
        inputs()?;
    }
    let mut request = ReportRequest::new(MACHINE, PAGE);
    request.data = Some(DATA.into());
    request.history = Some(HISTORY.into());
    request.export = Some(EXPORT.into());
    let r = report(request)?;
    print!("{}", r.report());
    Ok(())
}

/// The calibration, five daily checks and the export.
fn inputs() -> Result<(), Failure> {
    std::fs::create_dir_all("fixtures/report/checks")?;
    let fit = calibrate(CalibrateRequest::new(DATA))?;
    fit.write_machine(Path::new(MACHINE), tricept_ident::WriteOptions::default())?;
    let description = MachineDescription::from_file(Path::new(MACHINE))?;
    let digest = description.calibration_digest();
    let date = description
        .calibration
        .as_ref()
        .map(|c| c.date.clone())
        .unwrap_or_default();
    let day0 = days_from_civil(&date).ok_or(format!("{MACHINE}: no date in `{date}`"))?;
    let _ = std::fs::remove_file(HISTORY);
    for day in 1..=5i64 {
        let truth = if day < 5 {
            TrueErrors::Table2
        } else {
            slipped("fixtures/report/checks/leg2-slipped.json", 0.025)?
        };
        let data = PathBuf::from(format!("fixtures/report/checks/day{day}.csv"));
        let mut r = SimulateRequest::new().machine(tricept_ident::MachineInput::default());
        r.truth = truth;
        r.poses = format!("random:20,{}", 40 + day).parse::<Poses>()?;
        r.seed = 40 + day as u64;
        let s = simulate(r)?;
        tricept_ident::advanced::files::write_path(&data, s.data(), s.comments())?;
        let c = check(CheckRequest::new(MACHINE, data.as_path()))?;
        let unix_s = ((day0 + day) * 86_400 + 6 * 3600 + 30 * 60) as f64;
        let entry = tricept_check::history::Entry {
            calibration_digest: digest.clone(),
            ..tricept_check::history::Entry::of(
                c.check_report(),
                &iso(day0 + day, 6 * 3600 + 30 * 60),
                unix_s,
                MACHINE,
                &data.display().to_string(),
            )
        };
        tricept_check::history::append(Path::new(HISTORY), &entry)?;
        println!("day {day}: {}", c.check_report().verdict.as_str());
    }
    // The history's lock file (left in place by design) is no input.
    let _ = std::fs::remove_file(format!("{HISTORY}.lock"));
    let e = export(ExportRequest::new(
        MACHINE,
        ExportOptions::for_model(ControlModel::default()),
        EXPORT,
    ))?;
    println!("export written: {}", e.written());
    Ok(())
}

/// The Table 2 errors with leg 2 `slip_mm` longer, written as a `--truth`
/// file at `path`.
fn slipped(path: &str, slip_mm: f64) -> Result<TrueErrors, Failure> {
    let set = ParameterSet::paper15();
    let mut values = set.table2();
    let k = set
        .names()
        .iter()
        .position(|n| n == "dq2")
        .ok_or("no dq2 in paper15")?;
    values[k] += slip_mm;
    let text =
        serde_json::to_string_pretty(&serde_json::Value::Object(set.values_to_map(&values)))?;
    tricept_ident::advanced::files::write_atomic(Path::new(path), |w| {
        w.write_all(text.as_bytes())
    })?;
    Ok(TrueErrors::File(path.into()))
}

/// Days since 1970-01-01 of an ISO 8601 date (`2026-01-05...`), by H.
/// Hinnant's `days_from_civil`.
fn days_from_civil(date: &str) -> Option<i64> {
    let y: i64 = date.get(0..4)?.parse().ok()?;
    let m: i64 = date.get(5..7)?.parse().ok()?;
    let d: i64 = date.get(8..10)?.parse().ok()?;
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * (m + if m > 2 { -3 } else { 9 }) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    Some(era * 146_097 + doe - 719_468)
}

/// ISO 8601 UTC of a day count and the seconds into it, by Hinnant's
/// `civil_from_days`.
fn iso(days: i64, seconds: i64) -> String {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        seconds / 3600,
        seconds % 3600 / 60,
        seconds % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_round_trip_through_day_counts() {
        assert_eq!(days_from_civil("1970-01-01T00:00:00Z"), Some(0));
        assert_eq!(days_from_civil("2000-03-01"), Some(11_017));
        for day in [0, 59, 60, 11_016, 20_454, 20_819] {
            assert_eq!(days_from_civil(&iso(day, 0)), Some(day));
        }
        assert_eq!(iso(20_454, 23_400), "2026-01-01T06:30:00Z");
    }
}
