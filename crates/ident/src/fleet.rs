//! Fleet: the machines of a batch calibrated together (`tricept fleet`,
//! `docs/fleet.md`): the batch's systematic error with its uncertainty, the
//! machine-to-machine spread, each machine with the batch as its prior, the
//! machines that do not belong, and the prior a new machine of the batch
//! calibrates from (`identify --prior`).
//!
//! [`fleet`] takes a [`FleetRequest`] (one data file per machine, the
//! nominal machine) and returns a [`FleetResult`]: its JSON, report, exit
//! code and the prior file it writes. The computation is `tricept-fleet`'s.
//!
//! # Example
//! ```no_run
//! use tricept_ident::DataInput;
//! use tricept_ident::fleet::{FleetRequest, fleet};
//! let data: Vec<DataInput> = ["m1.csv", "m2.csv", "m3.csv"].into_iter().map(DataInput::from).collect();
//! let result = fleet(FleetRequest::new(data))?;
//! for machine in &result.batch().machines {
//!     println!("{machine:?}");
//! }
//! # Ok::<(), tricept_ident::Error>(())
//! ```

use std::path::{Path, PathBuf};

use serde_json::Value;
use tricept_data::Dataset;
use tricept_engine::{
    IdentifyOptions, accuracy::AccuracyModel, accuracy::accuracy_points, model::GeometricModel,
};
use tricept_fleet::{
    BatchOptions, PriorFile, calibrate_batch, prior_file::DataFileRecord,
    prior_file::PriorProvenance,
};
use tricept_model::ParameterSet;

pub use crate::outcome::{WriteOptions, Written};
/// A pose a calibration set aside as a gross error: its index and line,
/// its deleted residual in noise standard deviations (`None`: the fitted
/// model cannot reach it).
///
/// # Example
/// ```no_run
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let result = fleet(FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into(), "m3.csv".into()]))?;
/// let batch = result.batch();
/// for machine in &batch.machines {
///     for pose in &machine.own.rejected {
///         println!("{} line {}: {:?} sigma", machine.own.source, pose.line, pose.residual_sigma);
///     }
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_engine::robust::Rejection;
/// A batch calibrated together ([`FleetResult::batch`]).
///
/// # Example
/// ```no_run
/// use tricept_ident::fleet::{Batch, FleetRequest, fleet};
/// let result = fleet(FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into(), "m3.csv".into()]))?;
/// let batch: &Batch = result.batch();
/// println!("{} parameters identifiable across {} machines", batch.identifiable.len(), batch.machines.len());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_fleet::Batch;
/// One machine's place in its batch: its own calibration, whether it is a
/// member (or why not), its distance, its estimate.
///
/// # Example
/// ```no_run
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let result = fleet(FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into(), "m3.csv".into()]))?;
/// let batch = result.batch();
/// let outliers = batch.machines.iter().filter(|m| m.outlier).count();
/// assert_eq!(outliers, batch.outliers().len());
/// assert_eq!(batch.machines.iter().filter(|m| m.in_batch).count(), batch.members());
/// for m in batch.machines.iter().filter(|m| !m.in_batch) {
///     println!("{} kept out: {:?}", m.own.source, m.kept_out);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_fleet::batch::MachineOutcome;
/// A sparse solve of a fleet's joint fit: the factorisation, its size
/// (unknowns, non-zeros, rows) and its time (s).
///
/// # Example
/// ```no_run
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let result = fleet(FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into(), "m3.csv".into()]))?;
/// let batch = result.batch();
/// let stats = &batch.joint.stats;
/// assert!(stats.nonzeros <= stats.rows * stats.unknowns); // a sparse J
/// println!("{:?}: {} unknowns in {:.3} s", stats.kind, stats.unknowns, stats.seconds);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_fleet::batch::SolveStats;
/// The sparse solver of a fleet's joint fit.
///
/// # Example
/// ```
/// use tricept_ident::fleet::{FleetRequest, SolverKind};
/// let request = FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into()]);
/// assert_eq!(request.solver, "schur".parse::<SolverKind>()?);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_fleet::batch::SolverKind;
/// The joint fit of a batch: each member's parameters and offsets, the
/// batch mean with its covariance, the chi-squares, the solve.
///
/// # Example
/// ```no_run
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let result = fleet(FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into(), "m3.csv".into()]))?;
/// let batch = result.batch();
/// let joint = &batch.joint;
/// assert_eq!(joint.mean.len(), batch.identifiable.len());
/// assert_eq!(joint.parameters.len(), batch.members());
/// assert_eq!(joint.offsets.len(), batch.members());
/// assert!(joint.parameters.iter().all(|p| p.len() == batch.names.len()));
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_fleet::joint::JointFit;
/// One machine's calibration from its own data: its identification (or why
/// not), the poses rejected and kept, and its exit code.
///
/// # Example
/// ```no_run
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let result = fleet(FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into(), "m3.csv".into()]))?;
/// let batch = result.batch();
/// for own in batch.machines.iter().map(|m| &m.own) {
///     assert!([0, 2, 3, 4].contains(&own.exit_code));
///     if own.id.is_none() {
///         assert!(own.reason.is_some(), "a failed fit says why");
///     }
///     println!("{}: exit {} {:?}", own.source, own.exit_code, own.reason);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_fleet::own::OwnFit;
/// A machine against the rest of its batch: the chi-square of its estimate's
/// distance from the others' mean, its degrees of freedom, and each
/// parameter's `z`.
///
/// # Example
/// ```no_run
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let result = fleet(FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into(), "m3.csv".into()]))?;
/// let batch = result.batch();
/// for machine in &batch.machines {
///     if let Some(d) = &machine.distance {
///         assert_eq!(d.dof, batch.identifiable.len());
///         println!("{}: T = {:.1} ({} dof)", machine.own.source, d.chi_square, d.dof);
///     }
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_fleet::reml::Distance;
/// The spread of a fleet's parameters between machines (REML): each
/// parameter's variance with its uncertainty, and the batch mean.
///
/// # Example
/// ```no_run
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let result = fleet(FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into(), "m3.csv".into()]))?;
/// let batch = result.batch();
/// let spread = &batch.spread;
/// for (tau_mm, variance) in spread.spread_mm().iter().zip(&spread.variance) {
///     assert!((tau_mm * tau_mm - variance.max(0.0)).abs() < 1e-12);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_fleet::reml::Spread;

use crate::Setting;
use crate::data_input::DataInput;
use crate::error::Error;
use crate::inputs::LoadedMachine;
use crate::machine_input::MachineInput;

/// A batch to calibrate.
///
/// # Example
/// ```no_run
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let result = fleet(FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into(), "m3.csv".into()]))?;
/// println!("{}", result.to_json()["batch_spread_mm"]);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct FleetRequest {
    /// One campaign per machine (at least three).
    pub data: Vec<DataInput>,
    /// The batch's nominal machine (default: the embedded Table 1 machine).
    pub machine: MachineInput,
    /// The geometric parameters (default `paper15`).
    pub parameter_set: ParameterSet,
    /// Manufacturing tolerance per parameter, mm: each machine's campaign
    /// is judged worth deploying as `identify` judges it.
    pub tolerance_mm: f64,
    /// The factorisation of the joint fit (default the block elimination).
    pub solver: SolverKind,
}

impl FleetRequest {
    /// The batch of `data` (one file per machine) on the Table 1 machine.
    pub fn new(data: Vec<DataInput>) -> FleetRequest {
        FleetRequest {
            data,
            machine: MachineInput::default(),
            parameter_set: ParameterSet::paper15(),
            tolerance_mm: tricept_engine::accuracy::DEFAULT_TOLERANCE_MM,
            solver: SolverKind::Schur,
        }
    }
}

crate::request::setters!(FleetRequest {
    machine: into MachineInput,
    parameter_set: ParameterSet,
    tolerance_mm: f64,
    solver: SolverKind,
});

/// A batch calibrated.
///
/// # Example
/// ```no_run
/// use tricept_ident::DataInput;
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let data: Vec<DataInput> = ["m1.csv", "m2.csv", "m3.csv"].into_iter().map(DataInput::from).collect();
/// let result = fleet(FleetRequest::new(data))?;
/// for machine in &result.batch().machines {
///     println!("{machine:?}");
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug)]
pub struct FleetResult {
    loaded: LoadedMachine,
    batch: Batch,
    parameter_set: String,
    files: Vec<Option<PathBuf>>,
    reason: Option<String>,
}

crate::outcome::outcome!(FleetResult);

/// Calibrates the batch of `request` (module docs). Errors: bad files and
/// fewer than three machines whose data fit are input errors (exit 2).
///
/// # Example
/// ```no_run
/// use tricept_ident::DataInput;
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let data: Vec<DataInput> = ["m1.csv", "m2.csv", "m3.csv"].into_iter().map(DataInput::from).collect();
/// let result = fleet(FleetRequest::new(data))?;
/// for machine in &result.batch().machines {
///     println!("{machine:?}");
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn fleet(request: FleetRequest) -> Result<FleetResult, Error> {
    let tolerance = request.tolerance_mm;
    if !(tolerance.is_finite() && tolerance > 0.0 && tolerance <= 10.0) {
        return Err(Error::invalid(
            Setting::ToleranceMm,
            format!(
                "the manufacturing tolerance must be a number of mm above 0 and at most 10, got {tolerance}"
            ),
        ));
    }
    let loaded = request.machine.load()?;
    let m = loaded.machine();
    let set = &request.parameter_set;
    let datasets = request
        .data
        .iter()
        .map(|d| d.load(m))
        .collect::<Result<Vec<Dataset>, Error>>()?;
    let mut model = GeometricModel::new(m.clone(), set.clone());
    if let Some(reference) = loaded.rank_reference()? {
        model = model.with_rank_reference(reference);
    }
    let accuracy = AccuracyModel::new(m, set, &accuracy_points(m), tolerance)
        .map_err(|e| Error::from_library(e).in_setting(Setting::ToleranceMm))?;
    let options = BatchOptions {
        kind: request.solver,
        ..BatchOptions::default()
    };
    let batch = calibrate_batch(
        &model,
        &datasets,
        &IdentifyOptions::for_machine(m),
        &accuracy,
        &options,
    )
    .map_err(|e| Error::with_context("fleet", e))?;
    let reason = (batch.exit_code() != 0).then(|| {
        format!(
            "{} (see the warnings)",
            batch
                .warnings
                .first()
                .map_or("the batch's fit did not converge", String::as_str)
        )
    });
    Ok(FleetResult {
        reason,
        loaded,
        batch,
        parameter_set: set.label().to_string(),
        files: request
            .data
            .iter()
            .map(|d| d.path().map(Path::to_path_buf))
            .collect(),
    })
}

impl FleetResult {
    /// The batch (every machine's outcome, the spread, the joint fit).
    pub fn batch(&self) -> &Batch {
        &self.batch
    }

    /// 0 every machine fits and belongs; 3 a machine is kept out (its own
    /// data, or an outlier: named), or the batch is not one population; 4
    /// the joint fit or the spread did not converge.
    pub fn exit_code(&self) -> u8 {
        self.batch.exit_code()
    }

    /// Why the exit code is not 0, in one phrase (`None` when it is 0):
    /// the batch's first warning. The `tricept` binary prints it after
    /// `fleet: exit CODE: `.
    pub fn reason(&self) -> Option<&str> {
        self.reason.as_deref()
    }

    /// The JSON of `tricept fleet --json` (`format_version` first, the
    /// batch's keys, and `machine`).
    pub fn to_json(&self) -> Value {
        let mut v = self.batch.to_json();
        if let Value::Object(o) = &mut v {
            o.insert(
                "machine".into(),
                self.loaded.description().name.clone().into(),
            );
            o.insert("parameter_set".into(), self.parameter_set.clone().into());
        }
        crate::outcome::versioned(v)
    }

    /// The text report (what `tricept fleet` prints).
    pub fn report(&self) -> String {
        self.batch.to_text()
    }

    /// Writes the prior a new machine of the batch calibrates from
    /// (`identify --prior`) at `path`, atomically. Refused (an error of
    /// the batch's exit code) when the batch estimate itself is not to be
    /// trusted (not converged, or not one population) unless `force`;
    /// machines kept out do not enter it and do not stop it
    /// ([`WriteOptions::force`] writes it anyway, saying so).
    pub fn write_prior(&self, path: &Path, options: WriteOptions) -> Result<Written, Error> {
        let b = &self.batch;
        let why = if !(b.joint.converged && b.spread.converged) {
            Some("the batch's fit did not converge".to_string())
        } else if b.not_one_population {
            Some("the batch may not be one population".to_string())
        } else {
            None
        };
        let code = match &why {
            None => 0,
            Some(_) => b.exit_code().max(tricept_fleet::own::EXIT_INADEQUATE),
        };
        let what = path.display().to_string();
        let forced = crate::machine_file::write_rule(
            &what,
            code,
            why.as_deref().unwrap_or(""),
            options.is_forced(),
        )?;
        let data_files = b
            .machines
            .iter()
            .zip(&self.files)
            .map(|(m, file)| {
                Ok(DataFileRecord {
                    file: m.own.source.clone(),
                    sha256: match file {
                        Some(p) => crate::machine_file::sha256_file(p)?,
                        None => String::new(),
                    },
                    in_batch: m.in_batch,
                })
            })
            .collect::<Result<Vec<_>, Error>>()?;
        let provenance = PriorProvenance {
            method: "fleet".into(),
            machines: b.machines.len(),
            members: b.members(),
            data_files,
            outliers: b.outliers().iter().map(|s| s.to_string()).collect(),
            solver: b.joint.stats.kind.name().into(),
            written_utc: crate::machine_file::utc_now(),
            tricept_version: env!("CARGO_PKG_VERSION").into(),
            forced: forced.clone(),
        };
        let machine =
            serde_json::to_value(self.loaded.nominal_description()).unwrap_or(Value::Null);
        let file = PriorFile::new(b, machine, &self.parameter_set, provenance);
        crate::calibrate::write_text(path, &(file.to_json() + "\n"))?;
        Ok(Written::new("prior", path, forced))
    }
}
