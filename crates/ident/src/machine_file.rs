//! Calibrated machine files: the identified geometry in the description
//! format that every `--machine` loads, with a `calibration` record of the
//! estimates, their uncertainties and correlations, the sensor offsets,
//! what was held and why, the fit's quality and its provenance.
//!
//! Transitional public module: the workflows of `calibrate` and
//! `diagnosis` write these files; the CLI's verbs call it until they call
//! the workflows.

use std::path::Path;

use nalgebra::DMatrix;
use serde_json::{Map, Value};
use sha2::{Digest, Sha256};
use tricept_engine::fusion::{Fusion, SourceKind};
use tricept_engine::{Identification, report::IdentifiabilityReport};
use tricept_kinematics::description::{
    CalibrationRecord, CorrelationsDescription, ExternalSourceRecord, HeldParameter,
    SensorOffsetsDescription,
};
use tricept_kinematics::{Machine, MachineDescription};

use crate::error::Error;
use crate::inputs::LoadedMachine;

/// What the record says beyond the fit itself.
pub struct Provenance<'a> {
    /// `identify` or `diagnose`.
    pub method: &'static str,
    /// The data file as given.
    pub data_file: &'a Path,
    /// Parameter set label.
    pub parameter_set: &'a str,
    /// Lines rejected as gross errors.
    pub rejected_lines: Vec<u64>,
    /// Adequacy of the model.
    pub adequate: bool,
    /// Why the fit is not to be trusted, when it was written with
    /// `--force` anyway ([`write_rule`]).
    pub forced: Option<String>,
    /// Warnings of the fit.
    pub warnings: Vec<String>,
    /// Effect parameters (`{name: {"value", "std_dev"}}`), for `diagnose`.
    pub effects: Map<String, Value>,
    /// How many of the fit's parameters are recorded as estimates (the
    /// geometric ones, and the head's of a fused fit; the rest are effects,
    /// recorded under `effects`).
    pub n_geometric: usize,
    /// External measurement files of a fused fit: the file and its record
    /// (the hash is filled in when written).
    pub external: Vec<(&'a Path, ExternalSourceRecord)>,
    /// Mean logged structure temperature of the campaign, °C.
    pub temperature_c: Option<f64>,
    /// The accuracy the file promises.
    pub accuracy: Option<tricept_kinematics::description::AccuracyRecord>,
}

/// The mean logged structure temperature of `data`, °C, when every pose
/// carries one.
pub fn mean_temperature_c(data: &tricept_data::Dataset) -> Option<f64> {
    let t: Option<Vec<f64>> = data.poses.iter().map(|p| p.temp_c).collect();
    t.filter(|t| !t.is_empty())
        .map(|t| t.iter().sum::<f64>() / t.len() as f64)
}

/// What the record needs of a fit, whether from the UP limb's data alone
/// ([`Identification`]) or fused with external measurements ([`Fusion`]).
pub struct FitRecord<'a> {
    names: &'a [String],
    estimate: &'a [f64],
    std_dev: &'a [Option<f64>],
    covariance: &'a DMatrix<f64>,
    report: &'a IdentifiabilityReport,
    offsets: [f64; 3],
    offsets_std_dev: [f64; 3],
    chi2_per_dof: f64,
    dof: usize,
    converged: bool,
    poses_used: usize,
}

impl<'a> FitRecord<'a> {
    /// The record of an identification from the UP limb's data.
    pub fn of_identification(id: &'a Identification) -> FitRecord<'a> {
        FitRecord {
            names: &id.names,
            estimate: &id.estimate,
            std_dev: &id.std_dev,
            covariance: &id.covariance,
            report: &id.report,
            offsets: id.offsets,
            offsets_std_dev: id.offsets_std_dev,
            chi2_per_dof: id.stats.reduced_chi_square,
            dof: id.stats.dof,
            converged: id.converged,
            poses_used: id.residuals.len(),
        }
    }

    /// The record of a fused fit: the union's report, the internal
    /// source's sensor offsets, the chi-square per degree of freedom of all
    /// sources together.
    pub fn of_fusion(fit: &'a Fusion) -> FitRecord<'a> {
        let internal = fit.sources.iter().find(|s| s.kind == SourceKind::Internal);
        let pick = |v: &[f64]| -> [f64; 3] {
            std::array::from_fn(|c| v.get(c).copied().unwrap_or(f64::NAN))
        };
        let chi2: f64 = fit.sources.iter().map(|s| s.chi_square).sum();
        let dof: f64 = fit.sources.iter().map(|s| s.redundancy).sum();
        FitRecord {
            names: &fit.names,
            estimate: &fit.estimate,
            std_dev: &fit.std_dev,
            covariance: &fit.covariance,
            report: &fit.report.union,
            offsets: internal.map_or([0.0; 3], |s| pick(&s.nuisance)),
            offsets_std_dev: internal.map_or([0.0; 3], |s| pick(&s.nuisance_std_dev)),
            chi2_per_dof: if dof > 0.0 { chi2 / dof } else { 0.0 },
            dof: dof.round().max(0.0) as usize,
            converged: fit.converged,
            poses_used: internal.map_or(0, |s| s.records),
        }
    }
}

/// The one rule for writing a calibration, shared by `identify`,
/// `diagnose`, the fused path and `compensate`: a fit whose exit code is 0
/// is deployed; one whose code is 3 (the model does not explain the data,
/// or the campaign cannot calibrate) or 4 (the fit did not converge) only
/// with `--force`, and the file then says so (`calibration.forced`, its
/// name, its first warning). `why` is the reason of a non-zero code.
///
/// Returns the reason a forced write carries (`None` for a trusted fit;
/// the caller warns that the file is written although `why`), or refuses
/// with the fit's exit code, naming `what` (the flag and file).
pub fn write_rule(what: &str, code: u8, why: &str, force: bool) -> Result<Option<String>, Error> {
    match (code, force) {
        (0, _) => Ok(None),
        (_, true) => Ok(Some(why.to_string())),
        (_, false) => Err(Error::new(
            crate::ErrorKind::of_exit_code(code),
            format!("{what}: not written: {why}"),
        )
        .with_cause(crate::ErrorCause::RefusedWrite)),
    }
}

/// SHA-256 of a file's bytes, lower-case hex.
pub fn sha256_file(path: &Path) -> Result<String, Error> {
    let bytes = std::fs::read(path).map_err(|e| Error::unreadable(path.display(), e))?;
    let digest = Sha256::digest(&bytes);
    Ok(digest.iter().map(|b| format!("{b:02x}")).collect())
}

/// The time files and histories are stamped with, in seconds since
/// 1970-01-01 00:00:00 UTC: the clock, or the environment variable
/// `SOURCE_DATE_EPOCH` when it holds a whole number of seconds (the
/// reproducible-builds convention: "The value MUST be an ASCII
/// representation of an integer with no fractional component"), so that
/// a rerun writes the same bytes.
pub(crate) fn now_unix_s() -> f64 {
    if let Some(secs) = std::env::var("SOURCE_DATE_EPOCH")
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
    {
        return secs as f64;
    }
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// The current UTC time as ISO 8601 (`2026-11-23T09:38:00Z`), of
/// [`now_unix_s`].
pub fn utc_now() -> String {
    let secs = now_unix_s() as u64;
    let (days, rem) = (secs / 86_400, secs % 86_400);
    let (y, m, d) = civil_from_days(days as i64);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// Proleptic Gregorian date of a day count from 1970-01-01 (H. Hinnant's
/// `civil_from_days`).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

/// The unit of a parameter, from its name (`_rad`, `_ppm`; else mm).
fn unit_of(name: &str) -> &'static str {
    if name.ends_with("_rad") {
        "rad"
    } else if name.ends_with("_ppm") {
        "ppm"
    } else {
        "mm"
    }
}

/// Why each held parameter was held, from the identifiability report;
/// `seen_by` names the data (the UP limb's sensors, or every fused source).
fn held(id: &FitRecord<'_>, reference: &str, seen_by: &str) -> Vec<HeldParameter> {
    let r = id.report;
    let s1 = r.singular_values.first().copied().unwrap_or(0.0);
    r.fixed
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let value = id
                .names
                .iter()
                .position(|n| n == name)
                .map_or(0.0, |j| id.estimate[j]);
            let reason = match r.unidentifiable.get(i) {
                Some(c) => format!(
                    "unidentifiable from {seen_by} on {reference}: the combination {} has singular value {:.1e} of the largest, below the rank tolerance {:.0e}; held at its prior value {value} {}",
                    c.to_text(),
                    if s1 > 0.0 { c.singular_value / s1 } else { 0.0 },
                    r.rank_tolerance,
                    unit_of(name)
                ),
                None => format!(
                    "held at its prior value {value} {} by the rank decision on {reference}",
                    unit_of(name)
                ),
            };
            HeldParameter {
                name: name.clone(),
                reason,
            }
        })
        .collect()
}

/// The correlation matrix of the estimated (not held) parameters among the
/// first `n` of the fit.
fn correlations(id: &FitRecord<'_>, n: usize) -> CorrelationsDescription {
    let free: Vec<usize> = (0..n.min(id.names.len()))
        .filter(|&j| id.std_dev[j].is_some())
        .collect();
    let c = id.covariance;
    CorrelationsDescription {
        names: free.iter().map(|&j| id.names[j].clone()).collect(),
        matrix: free
            .iter()
            .map(|&a| {
                free.iter()
                    .map(|&b| {
                        let d = (c[(a, a)] * c[(b, b)]).sqrt();
                        if d > 0.0 { c[(a, b)] / d } else { 0.0 }
                    })
                    .collect()
            })
            .collect(),
    }
}

/// The calibrated machine's description: `identified` (its geometry and
/// leg effects) with the controller parameters of `base` unless given, a
/// name that says it is calibrated, and the calibration record.
pub fn calibrated_description(
    base: &LoadedMachine,
    identified: &Machine,
    id: &FitRecord<'_>,
    p: Provenance<'_>,
    controller: Option<tricept_kinematics::description::ControllerDescription>,
) -> Result<MachineDescription, Error> {
    let nominal = base.nominal_description();
    let date = utc_now();
    let data_name = p.data_file.display().to_string();
    let mut d = identified.to_description();
    d.controller = controller.or(base.description().controller);
    let status = match (&p.forced, p.adequate) {
        (Some(why), _) => format!(" (FORCED: {why})"),
        (None, false) => " (the model does not explain the data)".to_string(),
        (None, true) => String::new(),
    };
    d.name = format!(
        "{}, calibrated {} from {}{status}",
        nominal.name,
        &date[..10],
        data_name
    );
    d.notes = Some(format!(
        "written by tricept {} {} from {}; the `calibration` record holds the estimates relative to `{}`, their standard deviations and correlations, and the fit's quality",
        env!("CARGO_PKG_VERSION"),
        p.method,
        data_name,
        base.description().name
    ));
    let n = p.n_geometric.min(id.names.len());
    let mut estimates = Map::new();
    let mut std_dev = Map::new();
    for j in 0..n {
        estimates.insert(id.names[j].clone(), id.estimate[j].into());
        std_dev.insert(
            id.names[j].clone(),
            id.std_dev[j].map_or(Value::Null, Value::from),
        );
    }
    let reference = format!("`{}`", nominal.name);
    d.calibration = Some(Box::new(CalibrationRecord {
        method: p.method.to_string(),
        parameter_set: p.parameter_set.to_string(),
        estimates_mm: estimates,
        std_dev_mm: std_dev,
        correlations: correlations(id, n),
        effects: p.effects,
        sensor_offsets: SensorOffsetsDescription {
            phi_rad: id.offsets[0],
            theta_rad: id.offsets[1],
            s_mm: id.offsets[2],
            std_dev: id.offsets_std_dev,
        },
        accuracy: p.accuracy,
        applies: Vec::new(),
        records: Vec::new(),
        held: held(
            id,
            &reference,
            if p.external.is_empty() {
                "the UP limb's sensors"
            } else {
                "the internal and external data together"
            },
        ),
        chi2_per_dof: id.chi2_per_dof,
        dof: id.dof,
        converged: id.converged,
        adequate: p.adequate,
        forced: p.forced.is_some(),
        warnings: p
            .forced
            .iter()
            .map(|why| format!("written although {why} (forced)"))
            .chain(p.warnings)
            .collect(),
        poses_used: id.poses_used,
        temperature_c: p.temperature_c,
        external_sources: p
            .external
            .iter()
            .map(|(file, record)| {
                Ok(ExternalSourceRecord {
                    sha256: sha256_file(file)?,
                    ..record.clone()
                })
            })
            .collect::<Result<_, Error>>()?,
        rejected_lines: p.rejected_lines,
        leg_tables_digest: d.leg_effects.tables_digest(),
        seal: None,
        data_file: data_name,
        data_sha256: sha256_file(p.data_file)?,
        date,
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        relative_to: base.description().name.clone(),
        relative_to_machine: base.description().calibration.as_ref().map(|_| {
            let mut b = base.description().clone();
            b.calibration = None;
            Box::new(b)
        }),
        nominal: Box::new(nominal),
    }));
    // What is written must load back.
    d.validate()
        .map_err(|e| Error::other(format!("the calibrated machine is not valid: {e}")))?;
    Ok(d)
}

/// A calibrated machine file not yet written: its description (with its
/// record) and the verdict of the fit it came from, written by the one
/// write rule (`identify --write-machine`'s). A result gives it
/// ([`crate::calibrate::Calibration::machine_file`],
/// [`crate::diagnosis::DiagnoseResult::machine_file`]) to be kept apart
/// from the result (as JSON: a Python binding pickles it) and written
/// later, with the same refusal as the result's own `write_machine`.
///
/// # Example
/// ```
/// use tricept_ident::calibrate::MachineFile;
/// let f = MachineFile::from_json("{}");
/// assert!(f.is_err());
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MachineFile {
    /// The calibrated machine with its record (forced when `code` is not
    /// 0: the only way it may be written).
    description: MachineDescription,
    /// The fit's exit code for the write rule: 0 may be written, 3 and 4
    /// only with `force`.
    code: u8,
    /// Why a non-zero code is not to be trusted.
    why: String,
}

impl MachineFile {
    /// The file of a fit whose exit code is `code` (`why`: the reason of a
    /// non-zero one) and whose description is `description` (built forced
    /// when `code` is not 0).
    pub(crate) fn new(description: MachineDescription, code: u8, why: String) -> MachineFile {
        MachineFile {
            description,
            code,
            why,
        }
    }

    /// The calibrated machine's description, with its record (not sealed:
    /// writing seals it).
    pub fn description(&self) -> &MachineDescription {
        &self.description
    }

    /// The description sealed, as [`MachineFile::write`] would write it
    /// now: what loads as a machine in memory.
    pub fn sealed(&self) -> MachineDescription {
        let mut d = self.description.clone();
        d.seal();
        d
    }

    /// Writes the file at `path` atomically by the write rule: a fit whose
    /// exit code is not 0 is refused (an error of that code) unless
    /// `force`; the record's `date` is the time of writing. Returns the
    /// warning of a forced write.
    pub fn write(&self, path: &Path, force: bool) -> Result<Option<String>, Error> {
        let what = path.display().to_string();
        let forced = write_rule(&what, self.code, &self.why, force)?;
        let mut d = self.description.clone();
        if let Some(c) = d.calibration.as_mut() {
            c.date = utc_now();
        }
        write(path, &d).map_err(|e| Error::not_written(path, &e))?;
        Ok(forced.map(|why| format!("{what}: written although {why} (forced)")))
    }

    /// The JSON text it is kept as.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// Reads it back from [`MachineFile::to_json`]'s text (an input error
    /// for any other text).
    pub fn from_json(text: &str) -> Result<MachineFile, Error> {
        serde_json::from_str(text).map_err(|e| {
            Error::input(format!("not a machine file kept by tricept: {e}")).with_source(e)
        })
    }
}

/// Writes a machine description to `path` atomically (a crash or a full
/// disk leaves the previous file), its calibration record sealed last
/// ([`MachineDescription::seal`]), so that a file loads back only as it
/// was written.
pub fn write(path: &Path, d: &MachineDescription) -> std::io::Result<()> {
    let mut sealed = d.clone();
    sealed.seal();
    let text = sealed.to_json() + "\n";
    tricept_data::write_atomic(path, |w| w.write_all(text.as_bytes()))
}

#[cfg(test)]
mod tests {
    use super::civil_from_days;

    #[test]
    fn civil_dates() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(20_780), (2026, 11, 23));
    }
}
