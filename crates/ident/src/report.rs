//! The report workflow (`tricept report`): one self-contained HTML page per
//! calibrated machine (`tricept-report`): the verdict at the top, the
//! platform error over the workspace before and after, the residuals, what
//! the calibration deploys and what was looked for, the daily checks and
//! the controller files; every value shown names the JSON it comes from,
//! and that JSON is in the page.
//!
//! A [`ReportRequest`] gathers the page's sources from what the other
//! workflows give: the machine file as loaded (an edited one is refused),
//! the compensation map at three heights ([`crate::compensate`]), the
//! campaign's diagnosis ([`crate::diagnosis`], from the machine the
//! calibration started from, on `data`, which must be the campaign the
//! record's SHA-256 names), the check history and its trends, and the
//! export's summary; a history or an export of another calibration is
//! refused (exit code 2) naming the file. The verdict's exit code: 3 when
//! the page says not to trust the machine, else 0.
//!
//! # Example
//! ```no_run
//! use tricept_ident::report::{Level, ReportRequest, report};
//! let page = report(ReportRequest::new("calibrated.json", "machine.html"))?;
//! if page.verdict().level != Level::Trusted {
//!     println!("{}", page.verdict().words);
//! }
//! # Ok::<(), tricept_ident::Error>(())
//! ```

use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use tricept_report::{Source, Sources};

use crate::Setting;
use crate::compensate::{Calibrated, CompensateRequest, compensate};
use crate::diagnosis::{DiagnoseRequest, diagnose};
use crate::error::{EXIT_INADEQUATE, EXIT_OK, Error};
use crate::inputs::LoadedMachine;
use crate::machine_file::sha256_file;
use crate::machine_input::MachineInput;

/// One reason of a page's verdict: the level it calls for, what it says,
/// and the values it reads ([`Verdict::reasons`], worst first).
///
/// # Example
/// ```
/// use tricept_ident::report::{Level, Reason, Shown};
/// let reason = Reason {
///     level: Level::Caution,
///     says: "the campaign's residuals are larger than its sensors' noise".into(),
///     shows: vec![Shown { src: "machine".into(), path: "/calibration/chi2_per_dof".into() }],
/// };
/// let json = serde_json::to_value(&reason)?;
/// assert_eq!(json["level"], "caution"); // as the page's JSON names it
/// assert_eq!(json["shows"][0]["path"], "/calibration/chi2_per_dof");
/// # Ok::<(), serde_json::Error>(())
/// ```
///
/// A page's verdict is its worst reason:
/// ```no_run
/// use tricept_ident::report::{Level, ReportRequest, report};
/// let page = report(ReportRequest::new("calibrated.json", "machine.html"))?;
/// let worst = page.verdict().reasons.iter().map(|r| r.level).max();
/// assert_eq!(worst.unwrap_or(Level::Trusted), page.verdict().level);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_report::verdict::Reason;
/// A value a verdict's reason reads: its source's id on the page and the
/// JSON pointer of the value in it.
///
/// # Example
/// ```
/// use tricept_ident::report::Shown;
/// let shown = Shown { src: "machine".into(), path: "/calibration/chi2_per_dof".into() };
/// let machine_file = serde_json::json!({"calibration": {"chi2_per_dof": 1.08}});
/// assert_eq!(machine_file.pointer(&shown.path), Some(&serde_json::json!(1.08)));
/// assert_eq!(serde_json::to_value(&shown)?["src"], "machine");
/// # Ok::<(), serde_json::Error>(())
/// ```
#[doc(inline)]
pub use tricept_report::verdict::Shown;

/// How far a calibrated machine can be trusted.
///
/// # Example
/// ```
/// use tricept_ident::report::Level;
/// let levels = [Level::Trusted, Level::Caution, Level::DoNotTrust];
/// assert_eq!(levels.iter().filter(|l| **l == Level::Trusted).count(), 1);
/// ```
#[doc(inline)]
pub use tricept_report::Level;
/// The verdict at the top of a machine's page ([`Report::verdict`]).
///
/// # Example
/// ```no_run
/// use tricept_ident::report::{Level, ReportRequest, Verdict, report};
/// let page = report(ReportRequest::new("calibrated.json", "machine.html"))?;
/// let verdict: &Verdict = page.verdict();
/// if verdict.level != Level::Trusted {
///     for reason in &verdict.reasons {
///         println!("{reason:?}");
///     }
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_report::Verdict;

/// The file of an export folder the page reads (`--export DIR`).
///
/// # Example
/// ```
/// use tricept_ident::report::EXPORT_SUMMARY;
/// let summary = std::path::Path::new("export").join(EXPORT_SUMMARY);
/// assert!(summary.starts_with("export"));
/// ```
pub const EXPORT_SUMMARY: &str = tricept_export::SUMMARY_FILE;

/// The lattice spacing of the page's compensation maps, mm.
///
/// # Example
/// ```
/// assert!(tricept_ident::report::MAP_SPACING_MM > 0.0);
/// ```
pub const MAP_SPACING_MM: f64 = 25.0;

/// What the page is made from, and where it goes.
///
/// # Example
/// ```no_run
/// use tricept_ident::report::{ReportRequest, report};
/// let request = ReportRequest::new("calibrated.json", "page.html").history("checks.jsonl");
/// let page = report(request)?;
/// println!("{}", page.report());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct ReportRequest {
    /// The calibrated machine file.
    pub machine: MachineInput,
    /// The campaign the calibration was made from (its residuals, what
    /// its diagnosis looked for, each term's gain).
    pub data: Option<PathBuf>,
    /// The check history (`tricept check --history`).
    pub history: Option<PathBuf>,
    /// An export folder (`tricept export --out DIR`).
    pub export: Option<PathBuf>,
    /// The page written (HTML).
    pub out: PathBuf,
}

impl ReportRequest {
    /// The page of `machine` alone, written to `out`.
    pub fn new(machine: impl Into<MachineInput>, out: impl Into<PathBuf>) -> ReportRequest {
        ReportRequest {
            machine: machine.into(),
            data: None,
            history: None,
            export: None,
            out: out.into(),
        }
    }
}

crate::request::setters!(ReportRequest {
    data: some into PathBuf,
    history: some into PathBuf,
    export: some into PathBuf,
});

/// A page written, and its verdict.
///
/// # Example
/// ```no_run
/// use tricept_ident::report::{Level, ReportRequest, report};
/// let page = report(ReportRequest::new("calibrated.json", "machine.html"))?;
/// if page.verdict().level != Level::Trusted {
///     println!("{}", page.verdict().words);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Report {
    verdict: Verdict,
    out: PathBuf,
    reason: Option<String>,
}

crate::outcome::outcome!(Report);

impl Report {
    /// The page's verdict.
    pub fn verdict(&self) -> &Verdict {
        &self.verdict
    }

    /// 3 when the page says not to trust the machine, else 0.
    pub fn exit_code(&self) -> u8 {
        match self.verdict.level {
            Level::DoNotTrust => EXIT_INADEQUATE,
            _ => EXIT_OK,
        }
    }

    /// Why the exit code is not 0 (`None` when it is 0): the page's
    /// verdict not to trust the machine.
    pub fn reason(&self) -> Option<&str> {
        self.reason.as_deref()
    }

    /// The text report (what `tricept report` prints): where the page
    /// went, the verdict and its reasons, one line each.
    pub fn report(&self) -> String {
        let mut s = format!(
            "report written to {}: {}: {}\n",
            self.out.display(),
            self.verdict.words,
            self.verdict.level.meaning()
        );
        for r in &self.verdict.reasons {
            s.push_str(&format!("  {}: {}\n", r.level.as_str(), r.says));
        }
        s
    }

    /// The verdict as JSON (what `tricept report --json` prints,
    /// `format_version` first), with the page's path.
    pub fn to_json(&self) -> Value {
        crate::outcome::versioned(
            json!({"out": self.out.display().to_string(), "verdict": self.verdict.to_json()}),
        )
    }
}

/// Gathers the page's sources, renders the page and writes it atomically.
///
/// # Example
/// ```no_run
/// use tricept_ident::report::{Level, ReportRequest, report};
/// let page = report(ReportRequest::new("calibrated.json", "machine.html"))?;
/// if page.verdict().level != Level::Trusted {
///     println!("{}", page.verdict().words);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn report(request: ReportRequest) -> Result<Report, Error> {
    let loaded = request.machine.clone().load()?;
    let sources = sources(&request, &loaded)?;
    let page = tricept_report::page(&sources).map_err(|e| Error::input(e.to_string()))?;
    crate::calibrate::write_text(&request.out, &page.html)?;
    let reason = matches!(page.verdict.level, Level::DoNotTrust).then(|| {
        format!(
            "the page says not to trust the machine: {}",
            page.verdict.words
        )
    });
    Ok(Report {
        verdict: page.verdict,
        out: request.out,
        reason,
    })
}

/// The page's sources.
fn sources(request: &ReportRequest, loaded: &LoadedMachine) -> Result<Sources, Error> {
    let name = loaded.source().to_string();
    let description = loaded.description();
    let (Some(record), Some(digest)) = (
        description.calibration.as_deref(),
        description.calibration_digest(),
    ) else {
        return Err(Error::input(format!(
            "{name}: holds no `calibration` record: a report is of a calibrated machine file (written by identify's or diagnose's `write_machine`)"
        )));
    };
    let machine = Source::new(
        "machine",
        "the calibrated machine file, as loaded (its record checked against its seal)",
        Some(name.clone()),
        serde_json::to_value(description).unwrap_or(Value::Null),
    );
    let diagnosis = match &request.data {
        Some(path) => Some(diagnosis(
            path,
            &record.data_sha256,
            &record.data_file,
            loaded,
        )?),
        None => None,
    };
    let (history, trends) = match &request.history {
        Some(path) => {
            let (h, t) = history(path)?;
            (Some(h), Some(t))
        }
        None => (None, None),
    };
    Ok(Sources {
        machine,
        calibration_digest: digest,
        maps: maps(loaded)?,
        diagnosis,
        history,
        trends,
        export: request.export.as_deref().map(export).transpose()?,
    })
}

/// The compensation map at the workspace's bottom, middle and top planes.
fn maps(loaded: &LoadedMachine) -> Result<Vec<Source>, Error> {
    let w = &loaded.machine().workspace;
    let heights = [w.z_min_mm, w.mid_plane_z_mm(), w.z_max_mm];
    heights
        .iter()
        .enumerate()
        .map(|(k, z)| {
            let mut r = CompensateRequest::new(Calibrated::MachineFile(loaded.clone().into()));
            r.force = true;
            r.plane_z_mm = Some(*z);
            r.spacing_mm = MAP_SPACING_MM;
            let c = compensate(r)?;
            // The page keeps the map's keys without the output's version.
            let mut v = crate::outcome::unversioned(c.to_json());
            let (map, _) = c.maps();
            v["spacing_mm"] = c.spacing_mm().into();
            v["points"] = json!({
                "x": map.targets_mm.iter().map(|p| p.x).collect::<Vec<_>>(),
                "y": map.targets_mm.iter().map(|p| p.y).collect::<Vec<_>>(),
                "correction_mm": map.errors_mm.iter().map(|e| e.norm()).collect::<Vec<_>>(),
            });
            Ok(Source::new(
                &format!("map-{}", k + 1),
                &format!(
                    "the compensation of the calibrated machine at plane_z {z} mm, spacing {MAP_SPACING_MM} mm (compensate's JSON), with the map's columns (map.csv) as points"
                ),
                None,
                v,
            ))
        })
        .collect()
}

/// The campaign's diagnosis, from the machine the calibration started
/// from; the campaign must be the one the record names by its SHA-256.
fn diagnosis(
    path: &Path,
    sha256: &str,
    recorded: &str,
    loaded: &LoadedMachine,
) -> Result<Source, Error> {
    let file = path.display().to_string();
    let found = sha256_file(path)?;
    if found != sha256 {
        return Err(Error::input(format!(
            "{file}: not the campaign of this calibration: its SHA-256 is {found}, the calibration record's (`calibration.data_sha256`, of {recorded}) is {sha256}"
        )));
    }
    let base = loaded
        .identified_against(format!(
            "the machine {} was calibrated from",
            loaded.source()
        ))?
        .ok_or_else(|| Error::input(format!("{}: no calibration record", loaded.source())))?;
    let d = diagnose(DiagnoseRequest::new(path).machine(base))?;
    // The page keeps the diagnosis' keys without the output's version.
    let json = crate::outcome::unversioned(d.to_json());
    Ok(Source::new(
        "diagnosis",
        "the diagnosis of the campaign (diagnose's JSON), from the machine the calibration started from",
        Some(file),
        json,
    ))
}

/// The history's lines and their trends.
fn history(path: &Path) -> Result<(Source, Source), Error> {
    let file = path.display().to_string();
    if !path.is_file() {
        return Err(Error::invalid(
            Setting::History,
            format!("{file}: no such check history (a check with a history writes one)"),
        ));
    }
    let entries = tricept_check::history::read(path)?;
    let lines: Vec<Value> = entries
        .iter()
        .map(|e| serde_json::to_value(e).unwrap_or(Value::Null))
        .collect();
    let trends = tricept_check::history::trends(&entries);
    Ok((
        Source::new(
            "history",
            "the check history's lines (a check's history)",
            Some(file),
            Value::Array(lines),
        ),
        Source::new(
            "trends",
            "the history's trends, as a check's JSON gives them (history.trends)",
            None,
            serde_json::to_value(trends).unwrap_or(Value::Null),
        ),
    ))
}

/// The export's summary.
fn export(dir: &Path) -> Result<Source, Error> {
    let path = dir.join(EXPORT_SUMMARY);
    let file = path.display().to_string();
    let text = tricept_data::bounded::read_json_text(&path).map_err(|e| {
        Error::invalid(
            Setting::Export,
            format!("{file}: {e}: not the folder an export wrote"),
        )
        .with_file_failure(crate::error::FileFailure::new(&file, &e))
        .with_source(e)
    })?;
    let newer = tricept_kinematics::description::newer_format(
        &text,
        "export summary",
        tricept_export::SUMMARY_FORMAT_VERSION,
    );
    if let Some(newer) = newer {
        return Err(Error::input(format!("{file}: {newer}")));
    }
    let json: Value = serde_json::from_str(&text)
        .map_err(|e| Error::input(format!("{file}: not an export summary: {e}")))?;
    Ok(Source::new(
        "export",
        "the export's summary (DIR/export.json in the folder an export wrote)",
        Some(file),
        json,
    ))
}
