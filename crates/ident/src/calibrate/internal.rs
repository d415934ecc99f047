//! The calibration from the UP limb's sensors alone: the robust fit of the
//! geometric parameters and the sensor offsets, its verdict (with the
//! likely causes of an inconsistent fit), the platform accuracy it
//! predicts and the advice of a campaign too small to calibrate; its JSON,
//! its text report and its calibrated machine file.

use std::fmt::Write as _;
use std::path::Path;

use serde_json::{Map, Value, json};
use tricept_data::Dataset;
use tricept_engine::IdentError;
use tricept_engine::{
    Identification, IdentifyOptions, accuracy::PredictedAccuracy, identify, model::GeometricModel,
    prior::Prior, robust::Rejection, robust::identify_robust, suspects::likely_causes,
    verdict::Verdict,
};
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_kinematics::{Machine, MachineDescription};

use super::advice::{campaign_advice, predicted_accuracy};
use super::checked::Checked;
use crate::Setting;
use crate::accuracy::Accuracy;
use crate::error::{EXIT_INADEQUATE, EXIT_NOT_CONVERGED, EXIT_OK, Error, exit_reason};
use crate::inputs::LoadedMachine;
use crate::machine_file;

/// A fit from the internal data, with everything the outputs need.
#[derive(Debug)]
pub(crate) struct InternalFit {
    /// The model (increments on the loaded machine, with its rank rule).
    pub model: GeometricModel,
    /// The identification on the kept poses.
    pub id: Identification,
    /// Poses rejected as gross errors.
    pub rejected: Vec<Rejection>,
    /// The verdict, with the likely causes of an inconsistent fit and the
    /// advice of a campaign too small to calibrate added to its warnings.
    pub verdict: Verdict,
    /// The platform accuracy the fit predicts, against the machine's
    /// tolerance.
    pub accuracy: PredictedAccuracy,
    /// Mean logged structure temperature of the data, °C.
    pub temperature_c: Option<f64>,
    /// The accuracy the calibrated machine file will deliver.
    pub promise: Accuracy,
    /// Its report line, made with it.
    pub promise_line: String,
    /// Several campaigns or a batch's prior: what pooling adds.
    pub pooled: Option<Box<super::pooling::Pooled>>,
}

/// What a calibration says, made once where the calibration is made: its
/// exit code and reasons, the exit line, the text report and the notices
/// for the error stream.
#[derive(Debug, Clone)]
pub(crate) struct Said {
    /// The exit code of the verdict.
    pub exit_code: u8,
    /// Why it is not to be trusted (empty when it is).
    pub reason: String,
    /// Why it must not be deployed (`None` when it may).
    pub refusal: Option<String>,
    /// Why the exit code is not 0 (`None` for 0).
    pub exit_reason: Option<String>,
    /// The text report.
    pub report: String,
    /// Lines for the error stream after the report.
    pub notices: Vec<String>,
}

impl Said {
    /// What the internal (or pooled) fit `f` of the data `name` says.
    pub(crate) fn of_internal(f: &InternalFit, loaded: &LoadedMachine, name: &str) -> Said {
        let exit_code = f.exit_code();
        let reason = f.reason();
        Said {
            exit_code,
            exit_reason: exit_reason(exit_code, &reason),
            reason,
            refusal: f.refusal().map(String::from),
            report: f.report(loaded, name),
            notices: Vec::new(),
        }
    }
}

/// The internal calibration of `dataset` (named `name`) and what it says,
/// made in one pass ([`fit`], [`Said::of_internal`]).
pub(crate) fn calibrated(
    c: &Checked,
    dataset: &Dataset,
    name: &str,
) -> Result<(InternalFit, Said), Error> {
    let f = fit(c, dataset, None)?;
    let said = Said::of_internal(&f, &c.loaded, name);
    Ok((f, said))
}

/// Identifies `c`'s set from `dataset` against its machine (robust unless
/// told not to), with a batch's `prior` when given; the rank rule of a
/// calibrated machine is its nominal machine's.
pub(crate) fn fit(
    c: &Checked,
    dataset: &Dataset,
    prior: Option<Prior>,
) -> Result<InternalFit, Error> {
    let (loaded, set, robust, tolerance_mm) = (&c.loaded, &c.set, c.robust, c.tolerance_mm);
    let m = &loaded.machine;
    let mut model = GeometricModel::new(m.clone(), set.clone());
    if let Some(reference) = loaded.rank_reference()? {
        model = model.with_rank_reference(reference);
    }
    if let Some(prior) = prior {
        model = model
            .with_prior(prior)
            .map_err(|e| Error::from_library(e).in_setting(Setting::Prior))?;
    }
    let options = IdentifyOptions::for_machine(m);
    let source = dataset.source.as_str();
    let (id, rejected) = if robust {
        identify_robust(&model, dataset, &options).map_err(|e| fit_error(source, e))?
    } else {
        (
            identify(&model, dataset, &options).map_err(|e| fit_error(source, e))?,
            Vec::new(),
        )
    };
    let mut verdict = id.verdict();
    if verdict.inconsistent {
        for c in likely_causes(m, set, dataset, &options, id.stats.reduced_chi_square) {
            verdict.warnings.push(format!(
                "likely cause: {} (undone, the data fit with chi2/dof {:.2})",
                c.description, c.chi2_per_dof
            ));
        }
    }
    let accuracy = predicted_accuracy(m, set, &id, tolerance_mm)?;
    if !accuracy.worthwhile {
        verdict
            .warnings
            .push(campaign_advice(m, set, &accuracy, id.residuals.len())?);
    }
    let kept = dataset.subset(|j| !rejected.iter().any(|r| r.pose == j));
    let (promise, promise_line) =
        crate::accuracy::of_geometric_fit(&model, m, &id, &kept, &options, tolerance_mm)?;
    Ok(InternalFit {
        pooled: None,
        promise,
        promise_line,
        model,
        id,
        rejected,
        verdict,
        accuracy,
        temperature_c: machine_file::mean_temperature_c(dataset),
    })
}

impl InternalFit {
    /// 0 converged, adequate and worthwhile; 3 converged but inadequate, or
    /// a campaign too small to calibrate; 4 not converged.
    pub fn exit_code(&self) -> u8 {
        if !self.verdict.converged {
            EXIT_NOT_CONVERGED
        } else if !self.verdict.adequate
            || !self.accuracy.worthwhile
            || self.pooled.as_ref().is_some_and(|p| p.refused().is_some())
        {
            EXIT_INADEQUATE
        } else {
            EXIT_OK
        }
    }

    /// Why the fit must not be deployed (`None` when it may).
    pub fn refusal(&self) -> Option<&'static str> {
        if !self.verdict.converged {
            Some("the fit did not converge")
        } else if self.verdict.inconsistent {
            Some("the data cannot come from the described machine")
        } else if !self.verdict.adequate {
            Some("the model does not explain the data")
        } else if !self.accuracy.worthwhile {
            Some("the campaign is too small to calibrate the machine")
        } else {
            self.pooled.as_ref().and_then(|p| p.refused())
        }
    }

    /// The reason of a non-zero exit code in one phrase, with the first
    /// likely cause when one was found.
    pub fn reason(&self) -> String {
        let why = self.refusal().unwrap_or("");
        match self
            .verdict
            .warnings
            .iter()
            .find_map(|w| w.strip_prefix("likely cause: "))
        {
            Some(cause) => format!("{why}; likely cause: {cause}"),
            None => why.to_string(),
        }
    }

    /// The identified machine.
    pub fn identified(&self) -> Machine {
        self.model.machine_at(&self.id.estimate)
    }

    /// The calibrated machine's description, its record saying `forced`.
    pub fn description(
        &self,
        loaded: &LoadedMachine,
        data: &Path,
        forced: Option<String>,
    ) -> Result<MachineDescription, Error> {
        let mut d = machine_file::calibrated_description(
            loaded,
            &self.identified(),
            &machine_file::FitRecord::of_identification(&self.id),
            machine_file::Provenance {
                method: "identify",
                data_file: data,
                parameter_set: self.model.parameter_set().label(),
                // The first campaign's lines; the others' are in their records.
                rejected_lines: self
                    .rejected
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| {
                        self.pooled.as_ref().is_none_or(|p| {
                            p.rejected_file(*i) == Some(data.display().to_string().as_str())
                        })
                    })
                    .map(|(_, r)| r.line)
                    .collect(),
                adequate: self.verdict.adequate,
                forced,
                warnings: self.verdict.warnings.clone(),
                effects: Map::new(),
                n_geometric: self.id.names.len(),
                external: Vec::new(),
                temperature_c: self.temperature_c,
                accuracy: Some(self.promise.record()),
            },
            None,
        )?;
        // The other campaigns and the prior are recorded with their hashes.
        if let (Some(p), Some(c)) = (&self.pooled, d.calibration.as_mut()) {
            c.external_sources.extend(p.sources()?);
        }
        Ok(d)
    }

    /// The JSON of `identify --json`.
    pub fn to_json(&self, loaded: &LoadedMachine, data_name: &str) -> Value {
        let id = &self.id;
        let mut v = id.to_json();
        if let Value::Object(o) = &mut v {
            // One standard deviation per estimate, with its unit: the
            // estimate's (what `std_dev` holds too, for scripts written
            // before), not the design's prediction at the starting point,
            // which `identifiability` reports.
            let estimates: Map<String, Value> = id
                .names
                .iter()
                .zip(&id.estimate)
                .map(|(n, v)| (n.clone(), (*v).into()))
                .collect();
            let sd = o.get("std_dev").cloned().unwrap_or(Value::Null);
            o.insert("estimates_mm".into(), Value::Object(estimates));
            o.insert("std_dev_mm".into(), sd);
            o.insert("rejected".into(), rejected_json(&self.rejected));
            o.insert("warnings".into(), self.verdict.warnings.clone().into());
            o.insert(
                "predicted_accuracy".into(),
                serde_json::to_value(self.accuracy).unwrap_or(Value::Null),
            );
            o.insert("worthwhile".into(), self.accuracy.worthwhile.into());
            o.insert("accuracy".into(), self.promise.to_json());
            o.insert("machine".into(), loaded.description().name.clone().into());
            o.insert("data_file".into(), data_name.into());
            if let Some(p) = &self.pooled {
                for (k, value) in p.json() {
                    o.insert(k.into(), value);
                }
            }
        }
        v
    }

    /// The text report: the verdict, its reason and the likely cause
    /// first, the estimates after.
    pub fn report(&self, loaded: &LoadedMachine, data_name: &str) -> String {
        let mut s = String::new();
        self.write_report(&mut s, loaded, data_name);
        s
    }

    fn write_report(&self, s: &mut String, loaded: &LoadedMachine, data: &str) {
        let id = &self.id;
        let a = &self.accuracy;
        let _ = writeln!(
            s,
            "verdict: {}, {}, {}",
            if self.verdict.converged {
                "converged"
            } else {
                "NOT converged"
            },
            if self.verdict.adequate {
                "adequate (the model explains the data to the sensor noise)"
            } else {
                "NOT adequate (the model does not explain the data)"
            },
            if a.worthwhile {
                "worthwhile (it at least halves the platform error)"
            } else {
                "NOT worthwhile (the campaign is too small to calibrate)"
            }
        );
        let _ = writeln!(s, "{}", self.promise_line);
        let (causes, others): (Vec<&String>, Vec<&String>) = self
            .verdict
            .warnings
            .iter()
            .partition(|w| w.starts_with("likely cause"));
        for w in causes.iter().chain(&others) {
            let _ = writeln!(s, "WARNING: {w}");
        }
        let _ = writeln!(
            s,
            "predicted platform error after calibration: {:.4} mm rms (up to {:.4} mm at one of {} points), against {:.4} mm without calibration ({} mm per parameter)",
            a.after_rms_mm, a.after_max_mm, a.points, a.before_rms_mm, a.tolerance_mm
        );
        for (i, r) in self.rejected.iter().enumerate() {
            let why = match r.residual_sigma {
                Some(z) => format!("a reading {z:.1} noise standard deviations off (gross error)"),
                None => "the fitted machine cannot reach its commands".to_string(),
            };
            let file = self
                .pooled
                .as_ref()
                .and_then(|p| p.rejected_file(i))
                .unwrap_or(data);
            let _ = writeln!(
                s,
                "rejected pose {} (line {} of {file}): {why}",
                r.pose + 1,
                r.line
            );
        }
        if let Some(p) = &self.pooled {
            s.push_str(&p.report());
        }
        let campaigns;
        let data = match &self.pooled {
            Some(p) if p.campaigns.len() > 1 => {
                campaigns = format!("the {} campaigns", p.campaigns.len());
                campaigns.as_str()
            }
            _ => data,
        };
        let _ = writeln!(
            s,
            "{} poses of {data} against `{}`, parameter set {}: {} in {} Gauss-Newton iterations",
            id.residuals.len(),
            loaded.description().name,
            self.model.parameter_set().label(),
            if id.converged {
                "converged"
            } else {
                "NOT converged"
            },
            id.iterations
        );
        if !(self.verdict.converged && self.verdict.adequate && a.worthwhile) {
            let _ = writeln!(
                s,
                "(the estimates below are not to be trusted as a calibration: see the verdict above)"
            );
        }
        let _ = writeln!(s, "{:>6} {:>12} {:>10}", "param", "estimate mm", "sd mm");
        for ((n, v), sd) in id.names.iter().zip(&id.estimate).zip(&id.std_dev) {
            let _ = match sd {
                Some(sd) => writeln!(s, "{n:>6} {v:>12.5} {sd:>10.5}"),
                None => writeln!(s, "{n:>6} {v:>12.5} {:>10}", "held"),
            };
        }
        let arcsec = RAD_PER_ARCSEC;
        let _ = writeln!(
            s,
            "sensor offsets: phi {:.6} rad, theta {:.6} rad, s {:.4} mm",
            id.offsets[0], id.offsets[1], id.offsets[2]
        );
        let (z, j) = id.stats.max_standardised;
        let _ = writeln!(
            s,
            "residual rms: phi {:.3} arcsec, theta {:.3} arcsec, s {:.3} um; chi2/dof {:.3} (dof {}, p = {:.2e}); largest {z:.1} sigma at pose {} (line {})",
            id.stats.rms[0] / arcsec,
            id.stats.rms[1] / arcsec,
            id.stats.rms[2] * 1e3,
            id.stats.reduced_chi_square,
            id.stats.dof,
            self.verdict.chi_square_p_value,
            j + 1,
            id.lines.get(j).copied().unwrap_or(0)
        );
        s.push_str(&id.report.to_text());
    }
}

/// The rejected poses as JSON: 1-based pose number, file line, size.
pub(crate) fn rejected_json(rejected: &[Rejection]) -> Value {
    Value::Array(
        rejected
            .iter()
            .map(
                |r| json!({"pose": r.pose + 1, "line": r.line, "residual_sigma": r.residual_sigma}),
            )
            .collect(),
    )
}

/// An identification error of the data `source`, with the line of a pose
/// that cannot be reached.
pub(crate) fn fit_error(source: &str, e: IdentError) -> Error {
    match &e {
        IdentError::Kinematics {
            line, source: k, ..
        } => Error::new(
            crate::Classify::kind(&e),
            format!("{source}: line {line}: the commands of this pose cannot be reached: {k}"),
        )
        .with_source(e),
        _ => Error::with_context(source, e),
    }
}
