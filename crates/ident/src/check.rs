//! The check workflow (`tricept check`): has the machine changed since its
//! calibration? A short check campaign from the machine's own sensors
//! tested against the calibration record of the machine file, with an
//! optional history (JSON lines, appended) and its trends.
//!
//! The verdict's exit code: 0 unchanged, 3 changed; 0 too for readings
//! noisier than stated with no change standing out beyond that noise, and
//! for a campaign whose gross readings were set aside and whose other poses
//! are unchanged, each with a warning ([`CheckResult::warnings`]); a machine
//! file without a calibration record and a campaign that cannot see a
//! change are input errors (exit code 2).
//!
//! # Example
//! ```no_run
//! use tricept_ident::check::{CheckRequest, check};
//! let result = check(CheckRequest::new("calibrated.json", "today.csv"))?;
//! if result.changed() {
//!     println!("changed since its calibration: exit code {}", result.exit_code());
//! }
//! # Ok::<(), tricept_ident::Error>(())
//! ```

use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use tricept_check::history::{Entry, append, trends};
use tricept_check::{CheckError, CheckOptions, Reference};

use crate::data_input::DataInput;
use crate::error::{EXIT_INADEQUATE, EXIT_OK, Error};
use crate::machine_input::MachineInput;

/// A check's report ([`CheckResult`]).
///
/// # Example
/// ```
/// use tricept_ident::check::{CheckReport, CheckVerdict};
/// fn summary(report: &CheckReport) -> String {
///     format!("{} poses, changed: {}", report.poses, report.changed)
/// }
/// # let _ = summary;
/// # let _: Option<CheckVerdict> = None;
/// ```
#[doc(inline)]
pub use tricept_check::CheckReport;
/// A check's verdict ([`CheckReport`]'s `verdict`).
///
/// # Example
/// ```
/// use tricept_ident::check::{CheckReport, CheckVerdict};
/// fn act_on(report: &CheckReport) -> &'static str {
///     match report.verdict {
///         CheckVerdict::Unchanged | CheckVerdict::NoisierThanStated => "keep the machine file",
///         CheckVerdict::Changed | CheckVerdict::ChangedUnexplained => "recalibrate",
///     }
/// }
/// # let _ = act_on;
/// ```
#[doc(inline)]
pub use tricept_check::CheckVerdict;
/// What a candidate change is: a leg, a base or platform joint, the legs'
/// thermal state, or a sensor's gain (in JSON, kebab-case).
///
/// # Example
/// ```
/// use tricept_ident::check::CandidateKind;
/// assert_eq!(serde_json::to_value(CandidateKind::BaseJoint)?, "base-joint");
/// assert_eq!(serde_json::to_value(CandidateKind::Sensor)?, "sensor");
/// # Ok::<(), serde_json::Error>(())
/// ```
#[doc(inline)]
pub use tricept_check::candidates::CandidateKind;
/// A change a check names (a set of them explains the readings together):
/// its estimate, the platform error it causes (um), its test, its aliases.
///
/// # Example
/// ```no_run
/// use tricept_ident::check::{CheckRequest, check};
/// let result = check(CheckRequest::new("calibrated.json", "today.csv"))?;
/// let report = result.check_report();
/// use tricept_ident::check::CandidateKind;
/// for change in &report.changes {
///     assert_eq!(change.std_dev.len(), change.estimate.len());
///     assert!(change.platform_mean_um <= change.platform_max_um);
///     if change.kind == CandidateKind::Sensor {
///         assert_eq!(change.platform_mean_um, 0.0); // a sensor does not move the platform
///     }
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_check::changes::Change;
/// The significance level a check tests a change at by default.
///
/// # Example
/// ```
/// use tricept_ident::check::{CheckRequest, DEFAULT_ALPHA};
/// assert_eq!(CheckRequest::new("calibrated.json", "today.csv").alpha, DEFAULT_ALPHA);
/// ```
#[doc(inline)]
pub use tricept_check::check::DEFAULT_ALPHA;
/// One quantity's trend over a check history ([`CheckResult::trends`]).
///
/// # Example
/// ```no_run
/// use tricept_ident::check::{CheckRequest, Trend, check};
/// let mut request = CheckRequest::new("calibrated.json", "today.csv");
/// request.history = Some("checks.jsonl".into());
/// let result = check(request)?;
/// let trends: &[Trend] = result.trends();
/// for t in trends {
///     println!("{} ({}): {:?}", t.name, t.unit, t.values.last());
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_check::history::Trend;
/// The noise of one logged reading per channel: encoders `phi` and `theta`
/// (arcsec), scale `s` (um).
///
/// # Example
/// ```no_run
/// use tricept_ident::check::{CheckRequest, check};
/// let result = check(CheckRequest::new("calibrated.json", "today.csv"))?;
/// let report = result.check_report();
/// let stated = &report.noise.stated;
/// assert!(stated.phi_arcsec > 0.0 && stated.s_um > 0.0);
/// println!("scale: {:.2} um seen, {:.2} um stated", report.noise.seen.s_um, stated.s_um);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_check::noise::ChannelNoise;
/// The noise a check campaign shows against the stated one: their ratio
/// (about 1 when as stated) and each channel's.
///
/// # Example
/// ```no_run
/// use tricept_ident::check::{CheckRequest, check};
/// let result = check(CheckRequest::new("calibrated.json", "today.csv"))?;
/// let report = result.check_report();
/// let noise = &report.noise;
/// if noise.factor > 2.0 {
///     println!("readings {:.1} times noisier than the machine file says", noise.factor);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_check::noise::NoiseSeen;
/// What a check says of one candidate: its estimated change with standard
/// deviations, its likelihood-ratio test, the change it detects.
///
/// # Example
/// ```no_run
/// use tricept_ident::check::{CandidateResult, CheckRequest, check};
/// let result = check(CheckRequest::new("calibrated.json", "today.csv"))?;
/// let candidates: &[CandidateResult] = &result.check_report().candidates;
/// for c in candidates {
///     assert!(c.fitted <= c.parameters.len() && c.estimate.len() == c.parameters.len());
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_check::parts::CandidateResult;
/// A chi-square test: statistic, degrees of freedom, p-value (and its log,
/// finite where the p-value underflows), critical value.
///
/// # Example
/// ```no_run
/// use tricept_ident::check::{CheckRequest, check};
/// let result = check(CheckRequest::new("calibrated.json", "today.csv"))?;
/// let report = result.check_report();
/// let fit = &report.consistency; // the calibrated machine against the campaign
/// assert!((0.0..=1.0).contains(&fit.p_value));
/// if fit.p_value > 1e-300 {
///     assert!((fit.ln_p_value - fit.p_value.ln()).abs() < 1e-9);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_check::parts::ChiSquare;
/// A pose a check set aside: its number and line, its deleted residual in
/// noise standard deviations, and the reading off the most.
///
/// # Example
/// ```no_run
/// use tricept_ident::check::{CheckRequest, check};
/// let result = check(CheckRequest::new("calibrated.json", "today.csv"))?;
/// let report = result.check_report();
/// for pose in &report.rejected {
///     let unit = if pose.column == "s" { "um" } else { "arcsec" };
///     assert_eq!(pose.unit, unit);
///     println!("line {}: {} off by {} {}", pose.line, pose.column, pose.residual, pose.unit);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_check::parts::Rejected;

/// A check campaign against a calibrated machine.
///
/// # Example
/// ```no_run
/// use tricept_ident::check::{CheckRequest, check};
/// let result = check(CheckRequest::new("calibrated.json", "today.csv"))?;
/// print!("{}", result.report());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CheckRequest {
    /// The calibrated machine (a machine file with its calibration record).
    pub machine: MachineInput,
    /// The check campaign's measured data (with `temp_c` the legs' thermal
    /// state is checked too).
    pub data: DataInput,
    /// Family-wise false-alarm probability of the verdict, in (0, 0.5).
    pub alpha: f64,
    /// A history (JSON lines) to append the check to; its trends are
    /// reported.
    pub history: Option<PathBuf>,
}

impl CheckRequest {
    /// A check of `data` against `machine` at the default false-alarm
    /// probability, without history.
    pub fn new(machine: impl Into<MachineInput>, data: impl Into<DataInput>) -> CheckRequest {
        CheckRequest {
            machine: machine.into(),
            data: data.into(),
            alpha: tricept_check::check::DEFAULT_ALPHA,
            history: None,
        }
    }
}

crate::request::setters!(CheckRequest {
    alpha: f64,
    history: some into PathBuf,
});

/// The history a check was appended to.
#[derive(Debug, Clone)]
struct History {
    file: PathBuf,
    checks: usize,
    trends: Vec<Trend>,
}

/// A check's report, its verdict and the history's trends.
///
/// # Example
/// ```no_run
/// use tricept_ident::check::{CheckRequest, check};
/// let result = check(CheckRequest::new("calibrated.json", "today.csv"))?;
/// for trend in result.trends() {
///     println!("{trend:?}");
/// }
/// if result.changed() {
///     println!("changed since its calibration: exit code {}", result.exit_code());
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct CheckResult {
    report: CheckReport,
    reference: String,
    machine: String,
    data: String,
    history: Option<History>,
    readings_per_pose: u32,
    reason: Option<String>,
}

crate::outcome::outcome!(CheckResult);

/// Runs the check: the reference from the machine's calibration record,
/// the data read, the history read (refused before the check when it
/// cannot be), the test, and the entry appended to the history.
///
/// # Example
/// ```no_run
/// use tricept_ident::check::{CheckRequest, check};
/// let result = check(CheckRequest::new("calibrated.json", "today.csv"))?;
/// if result.changed() {
///     println!("changed since its calibration: exit code {}", result.exit_code());
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn check(request: CheckRequest) -> Result<CheckResult, Error> {
    let loaded = &request.machine.load()?;
    let machine = loaded.source().to_string();
    let reference = Reference::from_description(loaded.description())
        .map_err(|e| Error::input(format!("{machine}: {e}")))?;
    let data_name = request.data.name();
    let data = request.data.load(loaded.machine())?;
    let alpha = request.alpha;
    if !(alpha > 0.0 && alpha < 0.5) {
        return Err(Error::invalid(
            crate::Setting::Alpha,
            format!("the false-alarm probability must lie between 0 and 0.5, got {alpha}"),
        ));
    }
    if let Some(h) = &request.history {
        // A history that cannot be read or replaced is refused before the
        // check runs.
        crate::error::check_output_path(crate::Setting::History, h)?;
        let entries = tricept_check::history::read(h)?;
        tricept_check::history::belongs_to(
            h,
            &entries,
            loaded.description().calibration_digest().as_deref(),
        )?;
    }
    let mut options = CheckOptions::for_machine(loaded.machine());
    options.alpha = alpha;
    let report = tricept_check::check(&reference, &data, &options).map_err(|e| match e {
        CheckError::Blind(_) => Error::with_context(&data_name, e),
        e => Error::from(e),
    })?;
    if report.is_blind() {
        return Err(Error::input(format!(
            "{data_name}: the check's poses cannot see a change: no leg or joint change of less than 1 mm would be detected ({} poses); plan them for a check (a plan's instrument `check`)",
            report.poses
        )));
    }
    let history = match &request.history {
        Some(path) => Some(append_to(
            path,
            &report,
            &machine,
            &data_name,
            loaded.description().calibration_digest(),
        )?),
        None => None,
    };
    let reason = changed_reason(&report, &data_name);
    Ok(CheckResult {
        report,
        reason,
        reference: reference.name().to_string(),
        machine,
        data: data_name,
        history,
        readings_per_pose: loaded.machine().sensors.readings_per_pose.max(1),
    })
}

/// What changed, one phrase, when the machine changed (`data`: the data
/// checked).
fn changed_reason(r: &CheckReport, data: &str) -> Option<String> {
    if !r.changed {
        return None;
    }
    let what = match r.most_likely {
        Some(i) if r.shortlist.len() > 1 => format!(
            "most likely {} (cannot be told apart from {})",
            r.candidates[i].name,
            r.shortlist[1..].join(", ")
        ),
        Some(i) => format!("most likely {}", r.candidates[i].name),
        None => "cause unknown".to_string(),
    };
    let what = if r.changes.len() > 1 {
        let names: Vec<&str> = r.changes.iter().map(|c| c.name.as_str()).collect();
        format!("{what}; the changes: {}", names.join(", "))
    } else {
        what
    };
    Some(format!(
        "the machine changed since its calibration ({data}): {what}"
    ))
}

/// Appends the check to the history at `path` and computes its trends.
/// The entry names the calibration by its digest
/// (`MachineDescription::calibration_digest`), so that a report can tell a
/// history of another calibration.
fn append_to(
    path: &Path,
    report: &CheckReport,
    machine: &str,
    data: &str,
    calibration_digest: Option<String>,
) -> Result<History, Error> {
    let time = crate::machine_file::utc_now();
    let unix_s = crate::machine_file::now_unix_s();
    let entry = Entry {
        calibration_digest,
        ..Entry::of(report, &time, unix_s, machine, data)
    };
    let entries = append(path, &entry)?;
    Ok(History {
        file: path.to_path_buf(),
        checks: entries.len(),
        trends: trends(&entries),
    })
}

impl CheckResult {
    /// The check's report: the verdict, the candidates, the most likely
    /// change (the text of [`CheckResult::report`] and the JSON of
    /// [`CheckResult::to_json`] are made from it).
    pub fn check_report(&self) -> &CheckReport {
        &self.report
    }

    /// Whether the machine changed since its calibration.
    pub fn changed(&self) -> bool {
        self.report.changed
    }

    /// 0 unchanged (also noisier than stated, and after gross readings
    /// were set aside: [`CheckResult::warnings`] says so), 3 changed.
    pub fn exit_code(&self) -> u8 {
        if self.changed() {
            EXIT_INADEQUATE
        } else {
            EXIT_OK
        }
    }

    /// Why the exit code is not 0, in one phrase (`None` when it is 0):
    /// the machine changed, its most likely change and those it cannot be
    /// told apart from. The `tricept` binary prints it after `check: exit
    /// 3: `.
    pub fn reason(&self) -> Option<&str> {
        self.reason.as_deref()
    }

    /// What a person should know although the exit code is 0 or 3, one
    /// line each (the CLI prints them on stderr): readings noisier than
    /// stated, with the noise to state (per reading, as the
    /// `--angle-noise-arcsec` and `--length-noise-um` flags and the machine
    /// file's `sensors` take it), and each gross reading set aside, by its
    /// line.
    pub fn warnings(&self) -> Vec<String> {
        let r = &self.report;
        let mut out = Vec::new();
        if r.verdict == CheckVerdict::NoisierThanStated {
            let per_reading = f64::from(self.readings_per_pose).sqrt();
            let n = &r.noise.seen;
            out.push(format!(
                "{}: the readings are noisier than stated ({:.2} times; per logged reading phi {:.2} arcsec, theta {:.2} arcsec, s {:.2} um) and no change stands out beyond that noise: not a change of the machine; state the noise (angle_noise_arcsec {:.2}, length_noise_um {:.2}) or service the sensors",
                self.data,
                r.noise.factor,
                n.phi_arcsec,
                n.theta_arcsec,
                n.s_um,
                n.phi_arcsec.max(n.theta_arcsec) * per_reading,
                n.s_um * per_reading
            ));
        }
        for x in &r.rejected {
            out.push(format!(
                "{}: a gross reading set aside: line {} (pose {}), {} off by {:+.1} {}; the verdict comes from the other {} poses",
                self.data, x.line, x.pose, x.column, x.residual, x.unit, r.poses
            ));
        }
        out
    }

    /// The trends of the history's key quantities (empty without history).
    pub fn trends(&self) -> &[Trend] {
        self.history.as_ref().map_or(&[], |h| &h.trends)
    }

    /// The report as JSON (what `tricept check --json` prints,
    /// `format_version` first): the report's fields, the machine and data
    /// files, the history.
    pub fn to_json(&self) -> Value {
        let mut v = serde_json::to_value(&self.report).unwrap_or(Value::Null);
        if let Value::Object(o) = &mut v {
            o.insert("machine".into(), self.machine.clone().into());
            o.insert("data_file".into(), self.data.clone().into());
            if let Some(h) = &self.history {
                o.insert(
                    "history".into(),
                    json!({"file": h.file.display().to_string(), "checks": h.checks, "trends": h.trends}),
                );
            }
        }
        crate::outcome::versioned(v)
    }

    /// The report as text (what `tricept check` prints), with one line per
    /// trend of the history.
    pub fn report(&self) -> String {
        let mut out = format!(
            "check of {} against `{}` ({})\n",
            self.data, self.reference, self.machine
        );
        out.push_str(&self.report.to_text());
        if let Some(h) = &self.history {
            out.push_str(&format!(
                "history {} ({} checks):\n",
                h.file.display(),
                h.checks
            ));
            for trend in &h.trends {
                out.push_str(&format!("  {}\n", trend_text(trend)));
            }
        }
        out
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detectability::DetectabilityRequest;
    use crate::diagnosis::DiagnoseRequest;
    use crate::inputs::{LoadedMachine, SensorNoise, load_machine};

    fn paper() -> LoadedMachine {
        load_machine(None, &SensorNoise::default()).unwrap()
    }

    #[test]
    fn a_machine_without_calibration_record_cannot_be_checked() {
        let e = check(CheckRequest::new(paper(), "data.csv")).unwrap_err();
        assert_eq!(e.exit_code(), crate::EXIT_INPUT);
        assert!(
            e.message().starts_with("the built-in Table 1 machine: "),
            "{}",
            e.message()
        );
    }

    #[test]
    fn missing_data_exit_with_the_same_code_from_every_workflow() {
        let missing = "no-such-dir/today.csv";
        let d =
            crate::diagnosis::diagnose(DiagnoseRequest::new(missing).machine(paper())).unwrap_err();
        let mut r = DetectabilityRequest::new(crate::inputs::Poses::grid()).machine(paper());
        r.data = Some(missing.into());
        let t = crate::detectability::detectability(r).unwrap_err();
        for e in [d, t] {
            assert_eq!(e.exit_code(), crate::EXIT_INPUT);
            assert!(e.message().starts_with(missing), "{}", e.message());
        }
    }

    #[test]
    fn a_check_against_its_own_calibration_is_unchanged_and_kept_in_the_history() {
        let data = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/data/table2-grid-seed1.csv"
        );
        let dir = std::env::temp_dir().join(format!("tricept-door-check-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let machine = dir.join("calibrated.json");
        let history = dir.join("checks.jsonl");
        std::fs::remove_file(&history).ok();
        let d = crate::diagnosis::diagnose(DiagnoseRequest::new(data).machine(paper())).unwrap();
        d.write_machine(&machine, crate::WriteOptions::default())
            .unwrap();
        for n in 1..=2 {
            let loaded = load_machine(Some(&machine), &SensorNoise::default()).unwrap();
            let mut r = CheckRequest::new(loaded, data);
            r.history = Some(history.clone());
            let result = check(r).unwrap();
            assert!(!result.changed());
            assert_eq!(result.exit_code(), EXIT_OK);
            assert!(result.reason().is_none());
            let v = result.to_json();
            assert_eq!(v["history"]["checks"], n);
            assert_eq!(v["data_file"], data);
            assert!(!result.trends().is_empty());
            assert!(result.report().contains(&format!("({n} checks):")));
        }
        let mut r = CheckRequest::new(
            load_machine(Some(&machine), &SensorNoise::default()).unwrap(),
            data,
        );
        r.alpha = 0.7;
        let e = check(r).unwrap_err();
        assert_eq!(e.setting(), Some(crate::Setting::Alpha), "{e}");
        assert!(e.message().starts_with("alpha: "), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
