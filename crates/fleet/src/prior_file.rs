//! The prior file: what a batch says about a new machine of it, written by
//! `tricept fleet --write-prior` and read by `tricept identify --prior`
//! (`docs/fleet.md`, "The prior file").
//!
//! It holds the batch's nominal machine (its description, as the machine
//! files' `calibration.nominal` does), the parameter set, the predictive
//! distribution of a new machine's parameters (`mean_mm` and
//! `covariance_mm2`: the spread at its 95 % upper bound plus the mean's
//! uncertainty), the parameters the batch holds, the batch's own figures
//! for the record, and its provenance (every data file with its SHA-256,
//! which machines were in the batch, the outliers). It is sealed as a
//! machine file's record is ([`seal_digest`] of each field's compact
//! JSON): a hand edit of any sealed field is refused on load, by name.
//! Its `format_version` ([`PRIOR_FORMAT_VERSION`]) is sealed too; a file
//! without it is version 1 (as its seal, which then does not name it), and
//! a newer one is refused before anything else is read of it.

use std::collections::BTreeMap;

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use tricept_engine::prior::Prior;
use tricept_kinematics::description::{UNVERSIONED, newer_format, seal_digest};
use tricept_model::ParameterSet;

use crate::batch::Batch;
use crate::error::FleetError;

/// The format's name (`format` key).
pub const PRIOR_FORMAT: &str = "tricept-prior/1";

/// The prior file's format version this tricept writes and the newest it
/// reads (`format_version` key).
pub const PRIOR_FORMAT_VERSION: u32 = 1;

/// serde's default of `format_version`: a file without it is version 1.
fn unversioned() -> u32 {
    UNVERSIONED
}

/// A covariance by parameter name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NamedCovariance {
    /// The parameters, in the matrix's order.
    pub names: Vec<String>,
    /// The symmetric matrix, rows in that order.
    pub matrix: Vec<Vec<f64>>,
}

/// A data file of the batch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataFileRecord {
    /// The file as given.
    pub file: String,
    /// SHA-256 of its bytes.
    pub sha256: String,
    /// Whether its machine was in the batch estimates.
    pub in_batch: bool,
}

/// Where the prior came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PriorProvenance {
    /// `fleet`.
    pub method: String,
    /// Machines given.
    pub machines: usize,
    /// Machines in the batch estimates.
    pub members: usize,
    /// Every data file.
    pub data_files: Vec<DataFileRecord>,
    /// The outliers' data files.
    pub outliers: Vec<String>,
    /// The solver of the joint fit.
    pub solver: String,
    /// When it was written (UTC, ISO 8601).
    pub written_utc: String,
    /// The tricept version that wrote it.
    pub tricept_version: String,
    /// Why it was written although the batch is not to be trusted
    /// (`--force`), when it was.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub forced: Option<String>,
}

/// The prior file (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PriorFile {
    /// [`PRIOR_FORMAT_VERSION`] as written (absent: 1).
    #[serde(default = "unversioned")]
    pub format_version: u32,
    /// [`PRIOR_FORMAT`].
    pub format: String,
    /// What it is, for people.
    pub name: String,
    /// The batch's nominal machine description.
    pub machine: Value,
    /// The parameter set's label (`paper15`, `full21`).
    pub parameter_set: String,
    /// The predictive mean of a new machine's parameters (every parameter;
    /// held ones at zero), mm.
    pub mean_mm: Map<String, Value>,
    /// The parameters the batch holds (no machine's data see them).
    pub held: Vec<String>,
    /// The predictive covariance over the others, mm^2.
    pub covariance_mm2: NamedCovariance,
    /// The batch mean's standard deviations, mm (for the record).
    pub batch_mean_sd_mm: Map<String, Value>,
    /// The estimated spread, mm (for the record).
    pub batch_spread_mm: Map<String, Value>,
    /// The spread the covariance uses: its 95 % upper bound, mm.
    pub prior_spread_mm: Map<String, Value>,
    /// Where it came from.
    pub provenance: PriorProvenance,
    /// Digests of the sealed fields.
    pub seal: BTreeMap<String, String>,
}

/// `{name: value}` of the values that are there.
fn named(names: &[String], values: &[Option<f64>]) -> Map<String, Value> {
    names
        .iter()
        .zip(values)
        .filter_map(|(n, v)| v.map(|v| (n.clone(), v.into())))
        .collect()
}

impl PriorFile {
    /// The prior of `batch` (its nominal machine's description
    /// `machine`, parameter set label `parameter_set`), with its
    /// provenance, sealed.
    pub fn new(
        batch: &Batch,
        machine: Value,
        parameter_set: &str,
        provenance: PriorProvenance,
    ) -> PriorFile {
        let names = &batch.names;
        let (mean, cov) = batch.predictive();
        let (_, mean_sd) = batch.mean();
        let free: Vec<String> = batch
            .identifiable
            .iter()
            .map(|&j| names[j].clone())
            .collect();
        let mut file = PriorFile {
            format_version: PRIOR_FORMAT_VERSION,
            format: PRIOR_FORMAT.to_string(),
            name: format!(
                "prior of a batch of {} machines ({} in the batch estimates)",
                provenance.machines, provenance.members
            ),
            machine,
            parameter_set: parameter_set.to_string(),
            mean_mm: names
                .iter()
                .zip(&mean)
                .map(|(n, v)| (n.clone(), (*v).into()))
                .collect(),
            held: batch.held().iter().map(|&j| names[j].clone()).collect(),
            covariance_mm2: NamedCovariance {
                matrix: (0..free.len())
                    .map(|a| (0..free.len()).map(|b| cov[(a, b)]).collect())
                    .collect(),
                names: free,
            },
            batch_mean_sd_mm: named(names, &mean_sd),
            batch_spread_mm: named(names, &batch.spread_mm()),
            prior_spread_mm: named(names, &batch.spread_upper_mm()),
            provenance,
            seal: BTreeMap::new(),
        };
        file.seal = file.digests();
        file
    }

    /// The digests of the sealed fields (`format_version` unless a seal
    /// without it is checked and it is 1: a file written before it).
    fn digests(&self) -> BTreeMap<String, String> {
        let unversioned = self.format_version == UNVERSIONED
            && !self.seal.is_empty()
            && !self.seal.contains_key("format_version");
        let version = (!unversioned).then(|| ("format_version", seal_digest(&self.format_version)));
        [
            ("format", seal_digest(&self.format)),
            ("machine", seal_digest(&self.machine)),
            ("parameter_set", seal_digest(&self.parameter_set)),
            ("mean_mm", seal_digest(&self.mean_mm)),
            ("held", seal_digest(&self.held)),
            ("covariance_mm2", seal_digest(&self.covariance_mm2)),
            ("batch_mean_sd_mm", seal_digest(&self.batch_mean_sd_mm)),
            ("batch_spread_mm", seal_digest(&self.batch_spread_mm)),
            ("prior_spread_mm", seal_digest(&self.prior_spread_mm)),
            ("provenance", seal_digest(&self.provenance)),
        ]
        .into_iter()
        .chain(version)
        .map(|(k, v)| (k.to_string(), v))
        .collect()
    }

    /// The file's JSON text.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// A prior file read from `text` (of file `source`): its format, its
    /// seal (an edited field is refused by name) and its covariance's
    /// shape checked.
    ///
    /// # Example
    /// ```
    /// let e = tricept_fleet::PriorFile::from_json("{}", "p.json").unwrap_err();
    /// assert!(e.to_string().starts_with("p.json: not a prior file"), "{e}");
    /// ```
    pub fn from_json(text: &str, source: &str) -> Result<PriorFile, FleetError> {
        if let Some(newer) = newer_format(text, "prior file", PRIOR_FORMAT_VERSION) {
            return Err(FleetError::Input(format!("{source}: {newer}")));
        }
        let file: PriorFile =
            serde_json::from_str(text.trim_start_matches('\u{feff}')).map_err(|e| {
                FleetError::Input(format!("{source}: not a prior file ({PRIOR_FORMAT}): {e}"))
            })?;
        if file.format != PRIOR_FORMAT {
            return Err(FleetError::Input(format!(
                "{source}: format `{}`, not {PRIOR_FORMAT}",
                file.format
            )));
        }
        let edited: Vec<String> = file
            .digests()
            .into_iter()
            .filter(|(k, v)| file.seal.get(k) != Some(v))
            .map(|(k, _)| k)
            .collect();
        if !edited.is_empty() {
            return Err(FleetError::Input(format!(
                "{source}: the prior was edited after it was written (sealed fields changed: {}); write it again (a fleet's `write_prior`)",
                edited.join(", ")
            )));
        }
        let n = file.covariance_mm2.names.len();
        if file.covariance_mm2.matrix.len() != n
            || file.covariance_mm2.matrix.iter().any(|row| row.len() != n)
        {
            return Err(FleetError::Input(format!(
                "{source}: covariance_mm2 is not {n} x {n}"
            )));
        }
        Ok(file)
    }

    /// The engine's prior over `set`'s parameters: the set must be the
    /// one the batch was calibrated with.
    pub fn prior(&self, set: &ParameterSet) -> Result<Prior, FleetError> {
        if set.label() != self.parameter_set {
            return Err(FleetError::Input(format!(
                "the prior is of parameter set {}, the calibration of {}",
                self.parameter_set,
                set.label()
            )));
        }
        let names = set.names();
        let mean = names
            .iter()
            .map(|n| {
                self.mean_mm.get(n).and_then(Value::as_f64).ok_or_else(|| {
                    FleetError::Input(format!("the prior has no finite mean_mm of {n}"))
                })
            })
            .collect::<Result<Vec<f64>, _>>()?;
        let covers = self
            .covariance_mm2
            .names
            .iter()
            .map(|n| {
                set.index_of(n).ok_or_else(|| {
                    FleetError::Input(format!("the prior names `{n}`, not of {}", set.label()))
                })
            })
            .collect::<Result<Vec<usize>, _>>()?;
        let c = &self.covariance_mm2.matrix;
        let cov = DMatrix::from_fn(covers.len(), covers.len(), |a, b| c[a][b]);
        Prior::new(mean, &covers, &cov).map_err(|e| FleetError::Input(format!("the prior: {e}")))
    }
}
