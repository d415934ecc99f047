//! Calibrate: identify the machine's geometric errors from the UP limb's
//! sensors alone, from several campaigns of one machine or with a batch's
//! prior, or fused with external measurements (laser tracker, ballbar,
//! touch-offs) that also calibrate the head. A calibration states its
//! verdict and exit code, the accuracy it predicts on the platform, the
//! advice for a campaign too small to calibrate, and the calibrated
//! machine file it may write (under the one write rule of every machine
//! file the door writes).
//!
//! [`calibrate`] takes a [`CalibrateRequest`] (the data as a file or in
//! memory, the machine, the parameter set, the external sources) and
//! returns a [`Calibration`]: what `tricept identify` prints (its text
//! report, its JSON) and writes.
//!
//! # Example
//! ```no_run
//! use tricept_ident::calibrate::{CalibrateRequest, calibrate};
//! let calibration = calibrate(CalibrateRequest::new("campaign.csv"))?;
//! for (name, value, sigma) in calibration.estimates() {
//!     println!("{name} = {value} (+/- {sigma:?})");
//! }
//! # Ok::<(), tricept_ident::Error>(())
//! ```

// # The identify walk
//
// `tricept identify --data D` (text report, no machine file written),
// file by file in execution order. A stay is an arrival by a call made
// from the CLI or the door; an internal crate's file counts where the door
// calls it (its own calls are not followed); a run of calls from one
// place into one file (a loop, a builder) is one stay; constructors of the
// request's values and accessors that return a stored field are not
// stays. A *return* is a stay in a file the walk had already left
// (marked R).
//
// 1. `cli/src/main.rs`: parse, `run`
// 2. `cli/src/files.rs`: the paths' roles checked
// 3. `cli/src/ident_cmd.rs`: `run_identify`
// 4. `cli/src/args.rs`: `IdentifyArgs::prepare` (the flags in one pass:
//    their checks, the request, the spinner)
// 5. `ident/src/calibrate/mod.rs`: `calibrate`, `check`
// 6. `ident/src/machine_input.rs`: `MachineInput::load`
// 7. `ident/src/inputs.rs`: `load_machine`, `LoadedMachine::from_description`
// 8. `kinematics/src/description/`, `kinematics/src/machine.rs`: validate,
//    build, the workspace's reach
// 9. `ident/src/data_input.rs`: the data's name, `load`, `read_data`,
//    `check_commands`
// 10. `data/src/read.rs`: the CSV
// 11. `kinematics/src/machine.rs`: each pose's commands in the stroke (R)
// 12. `ident/src/calibrate/internal.rs`: `calibrated` (`fit`, then what it
//     says: [`Calibration`] keeps the exit code, reasons, exit line,
//     report and notices made here)
// 13. `ident/src/inputs.rs`: `rank_reference` (R)
// 14. `engine/src/model.rs`, `options.rs`, `robust.rs`, `verdict.rs`: the
//     robust fit and its verdict
// 15. `ident/src/calibrate/advice.rs` and `engine/src/accuracy/mod.rs`:
//     the predicted accuracy
// 16. `data/src/pose.rs`: the kept poses
// 17. `ident/src/accuracy.rs`: `of_geometric_fit`, through `diagnose`'s
//     model to `engine/src/accuracy/promise.rs` (`of_fit_stated`: the
//     promise with its report line)
// 18. `ident/src/machine_file.rs`: the mean temperature
// 19. `engine/src/report.rs`: the identification's table (the exit line
//     is the CLI's own, `ident_cmd.rs`, from the stored `reason()`)
// 20. `cli/src/output.rs`: the machine file's warnings
// 21. `cli/src/output.rs`: the report (R; between 20 and 21 the CLI reads
//     the stored report)
// 22. `cli/src/output.rs`: stdout flushed by `main` (R)
//
// 4 returns. Keep it so: a value the CLI prints is made where the
// calibration is made and stored, not recomputed by a getter.

mod advice;
mod checked;
mod fused;
mod internal;
mod pooled;
mod pooling;
pub(crate) mod values;

use std::path::{Path, PathBuf};

use serde_json::Value;
use tricept_kinematics::{Machine, MachineDescription};
use tricept_model::ParameterSet;

use crate::Setting;
pub use crate::accuracy::Accuracy;
use crate::data_input::DataInput;
use crate::error::Error;
pub(crate) use crate::error::exit_reason;
use crate::inputs::LoadedMachine;
pub use crate::linalg::DMatrix;
use crate::machine_file;
pub use crate::machine_file::MachineFile;
use crate::machine_input::MachineInput;
pub use crate::outcome::{WriteOptions, Written};
use checked::{Checked, Work};
use internal::Said;
pub(crate) use internal::fit_error;
pub use values::FusedSources;

/// What to calibrate from, and how.
///
/// # Example
/// ```no_run
/// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
/// let calibration = calibrate(CalibrateRequest::new("data.csv"))?;
/// println!("exit code {}", calibration.exit_code());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CalibrateRequest {
    /// The internal data (a machine file can be written only from data
    /// given as a file: its record holds the file's hash).
    pub data: DataInput,
    /// The machine (default: the embedded Table 1 machine).
    pub machine: MachineInput,
    /// The geometric parameters to identify (default `paper15`).
    pub parameter_set: ParameterSet,
    /// Reject poses with a gross reading error (default true).
    pub robust: bool,
    /// Manufacturing tolerance of each geometric parameter, mm (above 0,
    /// at most 10): the campaign must at least halve the platform error it
    /// gives.
    pub tolerance_mm: f64,
    /// External measurements and the head: the fused calibration.
    pub fused: Option<FusedSources>,
    /// The calibration is meant to be written as a machine file: what the
    /// format cannot carry (fitted effects) is refused before fitting.
    pub for_machine_file: bool,
    /// More campaigns of the same machine (`--data` given again): pooled
    /// with `data`, the geometry shared, each campaign with its own sensor
    /// offsets (`docs/fleet.md`).
    pub campaigns: Vec<DataInput>,
    /// A batch's prior (`tricept fleet --write-prior`): the calibration is
    /// then the maximum a posteriori estimate, and its accuracy promise
    /// carries the prior's uncertainty (`docs/fleet.md`).
    pub prior: Option<PathBuf>,
}

impl CalibrateRequest {
    /// The internal calibration of `data` on the Table 1 machine with the
    /// defaults.
    pub fn new(data: impl Into<DataInput>) -> CalibrateRequest {
        CalibrateRequest {
            data: data.into(),
            machine: MachineInput::default(),
            parameter_set: ParameterSet::paper15(),
            robust: true,
            tolerance_mm: tricept_engine::accuracy::DEFAULT_TOLERANCE_MM,
            fused: None,
            for_machine_file: false,
            campaigns: Vec::new(),
            prior: None,
        }
    }
}

crate::request::setters!(CalibrateRequest {
    machine: into MachineInput,
    parameter_set: ParameterSet,
    robust: bool,
    tolerance_mm: f64,
    fused: some FusedSources,
    for_machine_file: bool,
    campaigns: Vec<DataInput>,
    prior: some into PathBuf,
});

#[derive(Debug)]
enum Fit {
    Internal(Box<internal::InternalFit>),
    Fused(Box<fused::FusedFit>),
}

/// A calibration: the fit, its verdict and exit code, its report and JSON,
/// and the machine file it may write.
///
/// # Example
/// ```no_run
/// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
/// let calibration = calibrate(CalibrateRequest::new("campaign.csv"))?;
/// let n = calibration.estimates().len();
/// assert_eq!(calibration.covariance().nrows(), n);
/// for warning in calibration.warnings() {
///     eprintln!("{warning}");
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug)]
pub struct Calibration {
    loaded: LoadedMachine,
    data: DataInput,
    fit: Fit,
    said: Said,
}

crate::outcome::outcome!(writes Calibration);

/// Calibrates as `request` says: loads the machine, reads the data, fits
/// (fused when external sources are given), and judges the fit.
///
/// Errors are input errors (exit code 2) for bad files, flags and data too
/// small to fit; a fit that completes returns its verdict in
/// [`Calibration::exit_code`].
///
/// # Example
/// ```no_run
/// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
/// let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv");
/// let calibration = calibrate(CalibrateRequest::new(file))?;
/// assert!(calibration.converged() && calibration.adequate());
/// // Every estimate, with its standard uncertainty where it has one.
/// for (name, value, sigma) in calibration.estimates() {
///     println!("{name} = {value} ({sigma:?})");
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn calibrate(request: CalibrateRequest) -> Result<Calibration, Error> {
    let (checked, data, name, work) = check(request)?;
    let (fit, said) = match &work {
        Work::Pooled { datasets, prior } => {
            let f = pooled::fit(&checked, datasets, prior.as_deref())?;
            let said = Said::of_internal(&f, &checked.loaded, &name);
            (Fit::Internal(Box::new(f)), said)
        }
        Work::Internal(dataset) => {
            let (f, said) = internal::calibrated(&checked, dataset, &name)?;
            (Fit::Internal(Box::new(f)), said)
        }
        Work::Fused(w) => {
            let f = fused::fit(&checked, w)?;
            let code = f.exit_code();
            let refusal = (code != 0).then(|| f.refusal_reason());
            let said = Said {
                exit_code: code,
                reason: refusal.clone().unwrap_or_default(),
                refusal,
                exit_reason: f.exit_reason(),
                report: f.report(),
                notices: f
                    .fit
                    .warnings
                    .iter()
                    .map(|w| format!("warning: {w}"))
                    .collect(),
            };
            (Fit::Fused(Box::new(f)), said)
        }
    };
    Ok(Calibration {
        loaded: checked.loaded,
        data,
        fit,
        said,
    })
}

/// Checks `request` once: the tolerance, the machine, which fit, the data
/// (and a fused calibration's settings, [`fused`]).
fn check(request: CalibrateRequest) -> Result<(Checked, DataInput, String, Work), Error> {
    let tolerance_mm = request.tolerance_mm;
    if !(tolerance_mm.is_finite() && tolerance_mm > 0.0 && tolerance_mm <= 10.0) {
        return Err(Error::invalid(
            Setting::ToleranceMm,
            format!(
                "the manufacturing tolerance must be a number of mm above 0 and at most 10, got {tolerance_mm}"
            ),
        ));
    }
    let loaded = request.machine.load()?;
    let pooled = !request.campaigns.is_empty() || request.prior.is_some();
    if pooled && request.fused.is_some() {
        return Err(Error::input(
            "several campaigns or a prior with external measurements: not supported (pool the internal campaigns, or fuse one)",
        ));
    }
    let checked = Checked {
        set: request.parameter_set,
        robust: request.robust,
        tolerance_mm,
        loaded,
    };
    let m = &checked.loaded.machine;
    // The data's name and the data, read in one visit to `data_input.rs`.
    let name = request.data.name();
    let work = match &request.fused {
        None if pooled => Work::Pooled {
            datasets: std::iter::once(&request.data)
                .chain(&request.campaigns)
                .map(|d| d.load(m))
                .collect::<Result<_, Error>>()?,
            prior: request.prior,
        },
        None => Work::Internal(request.data.load(m)?),
        Some(x) => {
            let data = request.data.load(m)?;
            Work::Fused(Box::new(checked::fused(
                &checked,
                data,
                x,
                request.for_machine_file,
            )?))
        }
    };
    Ok((checked, request.data, name, work))
}

impl Calibration {
    /// The exit code of the verdict: 0 to be trusted; 3 converged but the
    /// model does not explain the data, the campaign is too small to
    /// calibrate, or (fused) a source cannot be checked or an estimate is
    /// implausible; 4 not converged.
    pub fn exit_code(&self) -> u8 {
        self.said.exit_code
    }

    /// Whether the fit converged.
    pub fn converged(&self) -> bool {
        match &self.fit {
            Fit::Internal(f) => f.verdict.converged,
            Fit::Fused(f) => f.fit.converged,
        }
    }

    /// Whether the model explains the data (fused: every source, every
    /// estimate plausible).
    pub fn adequate(&self) -> bool {
        match &self.fit {
            Fit::Internal(f) => f.verdict.adequate,
            Fit::Fused(f) => f.trusted(),
        }
    }

    /// Why the exit code is not 0, in one phrase (`None` when it is 0):
    /// the verdict with its first likely cause, or why a fused fit must
    /// not be deployed. The `tricept` binary prints it after `identify:
    /// exit CODE: `.
    pub fn reason(&self) -> Option<&str> {
        self.said.exit_reason.as_deref()
    }

    /// Why the calibration is not to be trusted, the phrase a forced
    /// machine file records (empty when it is).
    pub(crate) fn why(&self) -> String {
        self.said.reason.clone()
    }

    /// Why the calibration must not be deployed, in one phrase (`None`
    /// when it may): the internal fit's verdict; for a fused fit its
    /// reasons.
    pub(crate) fn refusal(&self) -> Option<String> {
        self.said.refusal.clone()
    }

    /// The poses rejected as gross errors (internal fit) as JSON: 1-based
    /// pose number, file line, size.
    pub(crate) fn rejected_json(&self) -> Value {
        match &self.fit {
            Fit::Internal(f) => internal::rejected_json(&f.rejected),
            Fit::Fused(_) => Value::Array(Vec::new()),
        }
    }

    /// The fit's warnings (likely causes, the campaign advice, unexplained
    /// sources, implausible estimates), one line each.
    pub fn warnings(&self) -> &[String] {
        match &self.fit {
            Fit::Internal(f) => &f.verdict.warnings,
            Fit::Fused(f) => &f.fit.warnings,
        }
    }

    /// The warnings the machine file loaded calls for (a forced or
    /// inadequate calibration it holds).
    pub fn machine_warnings(&self) -> &[String] {
        &self.loaded.warnings
    }

    /// Lines for the error stream after the report: a fused fit's
    /// warnings (`warning: ...`).
    pub fn notices(&self) -> Vec<String> {
        self.said.notices.clone()
    }

    /// The machine calibrated against, as loaded.
    pub fn loaded(&self) -> &LoadedMachine {
        &self.loaded
    }

    /// The identified machine, to command: its kinematics apply every
    /// effect it carries (the leg effects of the machine calibrated
    /// against, kept), as a machine file written from this calibration
    /// and loaded again does.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
    /// use tricept_ident::kinematics::Vector3;
    /// let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv");
    /// let calibration = calibrate(CalibrateRequest::new(file))?;
    /// let ik = calibration.identified().inverse(&Vector3::new(0.0, 0.0, 750.0))?;
    /// assert!(ik.legs_mm.iter().all(|q| q.is_finite()));
    /// # Ok::<(), tricept_ident::Error>(())
    /// ```
    pub fn identified(&self) -> crate::kinematics::Machine {
        crate::kinematics::Machine::from_geometry(self.identified_geometry())
    }

    /// The identified geometric machine (the fits' and the machine file's
    /// writer's view).
    pub(crate) fn identified_geometry(&self) -> Machine {
        match &self.fit {
            Fit::Internal(f) => f.identified(),
            Fit::Fused(f) => f.model.machine_at(&f.fit.estimate),
        }
    }

    /// The estimates by parameter name (mm, rad; fused: with the head and
    /// effects), with their standard deviations (`None`: held).
    pub fn estimates(&self) -> Vec<(String, f64, Option<f64>)> {
        let (names, estimate, sd) = match &self.fit {
            Fit::Internal(f) => (&f.id.names, &f.id.estimate, &f.id.std_dev),
            Fit::Fused(f) => (&f.fit.names, &f.fit.estimate, &f.fit.std_dev),
        };
        names
            .iter()
            .zip(estimate.iter())
            .zip(sd)
            .map(|((n, v), s)| (n.clone(), *v, *s))
            .collect()
    }

    /// The covariance of the estimates (mm², rad², mm·rad), in the order
    /// of [`Calibration::estimates`]; held parameters have zero rows.
    pub fn covariance(&self) -> &DMatrix {
        match &self.fit {
            Fit::Internal(f) => &f.id.covariance,
            Fit::Fused(f) => &f.fit.covariance,
        }
    }

    /// The JSON `tricept identify --json` prints (`format_version`
    /// first).
    pub fn to_json(&self) -> Value {
        let name = self.data.name();
        crate::outcome::versioned(match &self.fit {
            Fit::Internal(f) => f.to_json(&self.loaded, &name),
            Fit::Fused(f) => f.to_json(&self.loaded, &name),
        })
    }

    /// The accuracy the machine file this calibration writes promises (also
    /// the JSON's `accuracy` and the report's first lines).
    pub fn accuracy(&self) -> Option<&Accuracy> {
        Some(match &self.fit {
            Fit::Internal(f) => &f.promise,
            Fit::Fused(f) => f.accuracy(),
        })
    }

    /// The text report `tricept identify` prints.
    pub fn report(&self) -> String {
        self.said.report.clone()
    }

    /// The calibrated machine's description with its `calibration` record
    /// (`forced`: why it is written although not to be trusted).
    pub fn description(&self, forced: Option<String>) -> Result<MachineDescription, Error> {
        let Some(data) = self.data.path() else {
            return Err(Error::invalid(
                Setting::WriteMachine,
                "the calibration record holds the data file's hash: give the data as a file",
            ));
        };
        match &self.fit {
            Fit::Internal(f) => f.description(&self.loaded, data, forced),
            Fit::Fused(f) => f.description(&self.loaded, data, forced),
        }
    }

    /// The machine file this calibration may write, kept apart from it
    /// ([`MachineFile`]): the description (forced when
    /// the exit code is not 0) and the verdict the write rule applies. An
    /// input error for data given in memory (the record holds the data
    /// file's hash).
    pub fn machine_file(&self) -> Result<crate::machine_file::MachineFile, Error> {
        let code = self.exit_code();
        let why = self.why();
        let forced = (code != 0).then(|| why.clone());
        let d = self.description(forced)?;
        Ok(crate::machine_file::MachineFile::new(d, code, why))
    }

    /// Writes the calibrated machine file at `path` atomically, by the one
    /// write rule: a fit whose exit code is not 0 is refused (an error of
    /// that code) unless [`WriteOptions::force`], and the file then says it
    /// was forced. Data given in memory are an input error (the record
    /// holds the data file's hash).
    ///
    /// # Example
    /// ```no_run
    /// use tricept_ident::WriteOptions;
    /// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
    /// let calibration = calibrate(CalibrateRequest::new("data.csv"))?;
    /// let written = calibration.write_machine("calibrated.json".as_ref(), WriteOptions::default())?;
    /// assert!(written.forced().is_none());
    /// # Ok::<(), tricept_ident::Error>(())
    /// ```
    pub fn write_machine(&self, path: &Path, options: WriteOptions) -> Result<Written, Error> {
        let what = path.display().to_string();
        let code = self.exit_code();
        let refused = |e: Error| {
            if let Fit::Fused(f) = &self.fit {
                f.record_write(path, false);
            }
            e
        };
        let forced = machine_file::write_rule(&what, code, &self.why(), options.is_forced())
            .map_err(refused)?;
        let d = self.description(forced.clone())?;
        machine_file::write(path, &d).map_err(|e| Error::not_written(path, &e))?;
        if let Fit::Fused(f) = &self.fit {
            f.record_write(path, true);
        }
        Ok(Written::new("machine file", path, forced))
    }
}

/// Writes `text` to `path` atomically; on failure the previous file is
/// intact and the error (exit code 1) names the file.
pub(crate) fn write_text(path: &Path, text: &str) -> Result<(), Error> {
    tricept_data::write_atomic(path, |w| w.write_all(text.as_bytes()))
        .map_err(|e| Error::not_written(path, &e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture() -> PathBuf {
        PathBuf::from(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/data/table2-grid-seed1.csv"
        ))
    }

    #[test]
    fn data_in_memory_calibrate_as_the_file_does_but_write_no_machine_file() {
        let from_file = calibrate(CalibrateRequest::new(fixture())).unwrap();
        let mut dataset = tricept_data::read_path(&fixture()).unwrap();
        dataset.source = "numpy columns".into();
        let in_memory = calibrate(CalibrateRequest::new(dataset)).unwrap();
        assert_eq!(from_file.exit_code(), 0, "{}", from_file.report());
        assert_eq!(in_memory.exit_code(), from_file.exit_code());
        assert_eq!(in_memory.estimates(), from_file.estimates());
        assert_eq!(in_memory.to_json()["data_file"], "numpy columns");
        let e = in_memory
            .write_machine(
                &std::env::temp_dir().join("tricept-never-written.json"),
                WriteOptions::default(),
            )
            .unwrap_err();
        assert_eq!(e.exit_code(), crate::EXIT_INPUT, "{e}");
        assert!(e.message().contains("give the data as a file"), "{e}");
    }

    #[test]
    fn a_tolerance_out_of_range_is_an_input_error_before_anything_is_read() {
        let mut request = CalibrateRequest::new("no-such-file.csv");
        request.tolerance_mm = 0.0;
        let e = calibrate(request).unwrap_err();
        assert_eq!(e.exit_code(), crate::EXIT_INPUT);
        assert_eq!(e.setting(), Some(Setting::ToleranceMm), "{e}");
        assert!(e.message().starts_with("tolerance_mm: "), "{e}");
    }

    #[test]
    fn every_instrument_setting_is_checked_before_any_external_file_is_read() {
        // Both the tracker's and the ballbar's noise are wrong and their
        // files do not exist: the first setting is named, no file is.
        let mut request = CalibrateRequest::new(fixture());
        request.fused = Some(FusedSources {
            tracker: vec!["no-such-tracker.csv".into()],
            tracker_target: Some("tip".parse().unwrap()),
            tracker_sigma_um: -1.0,
            ballbar: vec!["no-such-ballbar.csv".into()],
            ballbar_sigma_um: 0.0,
            ..FusedSources::default()
        });
        let e = check(request).unwrap_err();
        assert_eq!(e.exit_code(), crate::EXIT_INPUT);
        assert_eq!(e.setting(), Some(Setting::TrackerSigmaUm), "{e}");
        // Settings right, files missing: the fit is checked, the files are
        // read by the fit.
        let mut request = CalibrateRequest::new(fixture());
        request.fused = Some(FusedSources {
            tracker: vec!["no-such-tracker.csv".into()],
            tracker_target: Some("tip".parse().unwrap()),
            ..FusedSources::default()
        });
        let (checked, _, _, work) = check(request).unwrap();
        let Work::Fused(w) = work else {
            panic!("a fused request is fused work")
        };
        assert_eq!(w.tracker.1.sigma_um, 10.0);
        assert!(w.touch.is_none());
        assert_eq!(
            checked.tolerance_mm,
            CalibrateRequest::new("x").tolerance_mm
        );
    }
}
