//! Several campaigns of one machine, a batch's prior, or both
//! (`docs/fleet.md`): the internal fit of every pose with one set of sensor
//! offsets per campaign and the prior's rows, then each campaign's share
//! and whether it agrees with the rest (`tricept_fleet`); a campaign that
//! disagrees is named and left out of the estimate.

use std::path::Path;

use serde_json::{Value, json};
use tricept_data::Dataset;
use tricept_engine::{ADEQUACY_ALPHA, IdentifyOptions, Prior};
use tricept_fleet::{Agreement, PriorFile, agreements, campaign_chi_squares, pool};
use tricept_kinematics::description::ExternalSourceRecord;
use tricept_model::ParameterSet;
use tricept_numerics::stats::chi2_sf;

use super::internal::{InternalFit, fit as internal_fit};
use crate::data_input::DataInput;
use crate::error::Error;
use crate::inputs::LoadedMachine;

/// What pooling adds to an internal fit.
#[derive(Debug)]
pub(crate) struct Pooled {
    /// Every campaign, in the order given.
    pub campaigns: Vec<CampaignRow>,
    /// The data files of the campaigns that disagree with the rest.
    pub disagreeing: Vec<String>,
    /// The prior, when there was one.
    pub prior: Option<PriorUsed>,
    /// The campaign file of each rejected pose, in the fit's order.
    rejected_files: Vec<String>,
}

/// One campaign's share of a pooled fit.
#[derive(Debug)]
pub(crate) struct CampaignRow {
    file: String,
    poses: usize,
    rejected_lines: Vec<u64>,
    offsets: Option<([f64; 3], [f64; 3])>,
    chi_square: f64,
    readings: usize,
    temperature_c: Option<f64>,
    agreement: Option<Agreement>,
    in_fit: bool,
}

/// The prior a calibration used.
#[derive(Debug)]
pub(crate) struct PriorUsed {
    file: String,
    sha256: String,
    machines: usize,
    members: usize,
    chi_square: f64,
    dof: usize,
}

/// The batch's prior in `path`, for `loaded` and `set`: its machine must
/// be the one calibrated.
fn read_prior(
    path: &Path,
    loaded: &LoadedMachine,
    set: &ParameterSet,
) -> Result<(Prior, PriorFile), Error> {
    let name = path.display().to_string();
    let text =
        tricept_data::read_json_text(path).map_err(|e| Error::input(format!("{name}: {e}")))?;
    let file =
        PriorFile::from_json(&text, &name).map_err(|e| Error::with_context("--prior", &e))?;
    let geometry = |v: Value| match v {
        Value::Object(mut o) => {
            for k in ["name", "notes", "sensors", "calibration"] {
                o.remove(k);
            }
            Value::Object(o)
        }
        v => v,
    };
    let ours = serde_json::to_value(loaded.nominal_description()).unwrap_or(Value::Null);
    if geometry(ours) != geometry(file.machine.clone()) {
        return Err(Error::input(format!(
            "--prior {name}: the batch's machine is not `{}` (give the batch's nominal machine with --machine)",
            loaded.description().name
        )));
    }
    let prior = file
        .prior(set)
        .map_err(|e| Error::with_context(format!("--prior {name}"), &e))?;
    Ok((prior, file))
}

/// Calibrates from the campaigns `inputs` (at least one) and the prior at
/// `prior` (module docs).
pub(crate) fn fit(
    loaded: &LoadedMachine,
    set: &ParameterSet,
    inputs: &[&DataInput],
    prior: Option<&Path>,
    robust: bool,
    tolerance_mm: f64,
) -> Result<InternalFit, Error> {
    let m = loaded.machine();
    let datasets = inputs
        .iter()
        .map(|d| d.load(m))
        .collect::<Result<Vec<Dataset>, Error>>()?;
    let (prior, prior_file) = match prior {
        Some(path) => {
            let (p, f) = read_prior(path, loaded, set)?;
            (Some(p), Some((path, f)))
        }
        None => (None, None),
    };
    let all = pool(&datasets);
    let options = IdentifyOptions::for_machine(m);
    let mut used = all.clone();
    let mut fit = internal_fit(loaded, set, &used, robust, tolerance_mm, prior.clone())?;
    let count = datasets.len();
    let mut tests = vec![None; count];
    let mut disagreeing = Vec::new();
    if count >= 2 {
        let kept = used.subset(|j| !fit.rejected.iter().any(|r| r.pose == j));
        let a = agreements(&fit.model, &kept, count, &options, ADEQUACY_ALPHA)
            .map_err(|e| Error::with_context("the campaigns' agreement", &e))?;
        tests = a.tests;
        disagreeing = a.disagreeing;
        // Three or more campaigns: the ones that disagree leave the fit.
        if !disagreeing.is_empty() && disagreeing.len() < count {
            used = all.subset(|j| !disagreeing.contains(&all.poses[j].campaign));
            fit = internal_fit(loaded, set, &used, robust, tolerance_mm, prior)?;
        }
    }
    let kept = used.subset(|j| !fit.rejected.iter().any(|r| r.pose == j));
    let shares = campaign_chi_squares(&fit.id, &kept, count, &m.sensors.logged_sigma());
    let campaigns = datasets
        .iter()
        .enumerate()
        .map(|(c, d)| {
            let c32 = c as u32;
            let of = |p: &tricept_data::MeasuredPose| p.campaign == c32;
            CampaignRow {
                file: d.source.clone(),
                poses: kept.poses.iter().filter(|p| of(p)).count(),
                rejected_lines: fit
                    .rejected
                    .iter()
                    .filter(|r| used.poses.get(r.pose).is_some_and(of))
                    .map(|r| r.line)
                    .collect(),
                offsets: fit
                    .id
                    .campaign_offsets
                    .iter()
                    .find(|o| o.campaign == c32)
                    .map(|o| (o.offsets, o.std_dev)),
                chi_square: shares[c].1,
                readings: shares[c].0,
                temperature_c: crate::machine_file::mean_temperature_c(d),
                agreement: tests[c],
                in_fit: used.poses.iter().any(of),
            }
        })
        .collect();
    let prior = match (prior_file, fit.id.prior_fit) {
        (Some((path, file)), Some(pf)) => Some(PriorUsed {
            file: path.display().to_string(),
            sha256: crate::machine_file::sha256_file(path)?,
            machines: file.provenance.machines,
            members: file.provenance.members,
            chi_square: pf.chi_square,
            dof: pf.dof,
        }),
        _ => None,
    };
    let disagreeing: Vec<String> = disagreeing
        .iter()
        .map(|&c| datasets[c as usize].source.clone())
        .collect();
    for file in &disagreeing {
        fit.verdict.warnings.push(format!(
            "campaign {file} disagrees with the rest: its readings do not share their geometry (the machine changed between them?); {}",
            if disagreeing.len() < count {
                "it is left out of the estimate"
            } else {
                "which of the campaigns changed cannot be told"
            }
        ));
    }
    if let Some(p) = &prior {
        let p_value = chi2_sf(p.chi_square, p.dof as f64);
        if p_value < ADEQUACY_ALPHA {
            fit.verdict.warnings.push(format!(
                "the machine is unlike the batch of {}: its estimate is chi2 {:.1} on {} from the batch's prior (p = {p_value:.1e}); calibrate it from a full campaign alone",
                p.file, p.chi_square, p.dof
            ));
        }
    }
    let rejected_files = fit
        .rejected
        .iter()
        .map(|r| {
            used.poses.get(r.pose).map_or_else(String::new, |p| {
                datasets[p.campaign as usize].source.clone()
            })
        })
        .collect();
    fit.pooled = Some(Box::new(Pooled {
        campaigns,
        disagreeing,
        prior,
        rejected_files,
    }));
    Ok(fit)
}

impl Pooled {
    /// Whether a campaign disagrees with the rest (exit code 3).
    pub fn refused(&self) -> Option<&'static str> {
        (!self.disagreeing.is_empty()).then_some("a campaign disagrees with the rest")
    }

    /// The campaign file of the fit's `i`-th rejected pose.
    pub fn rejected_file(&self, i: usize) -> Option<&str> {
        self.rejected_files.get(i).map(String::as_str)
    }

    /// The JSON keys pooling adds: `campaigns` (each campaign's file,
    /// poses, offsets, chi-square, temperature and agreement),
    /// `disagreeing_campaigns` and `prior`.
    pub fn json(&self) -> Vec<(&'static str, Value)> {
        let campaigns: Vec<Value> = self
            .campaigns
            .iter()
            .map(|c| {
                let offsets = c.offsets.map(|(o, sd)| {
                    json!({"phi_rad": o[0], "theta_rad": o[1], "s_mm": o[2],
                           "std_dev": {"phi_rad": sd[0], "theta_rad": sd[1], "s_mm": sd[2]}})
                });
                json!({
                    "data_file": c.file,
                    "in_fit": c.in_fit,
                    "poses": c.poses,
                    "rejected_lines": c.rejected_lines,
                    "offsets": offsets,
                    "chi_square": c.chi_square,
                    "readings": c.readings,
                    "temperature_c": c.temperature_c,
                    "agreement": c.agreement,
                })
            })
            .collect();
        let prior = self.prior.as_ref().map(|p| {
            json!({"file": p.file, "sha256": p.sha256, "machines": p.machines, "members": p.members,
                   "chi_square": p.chi_square, "dof": p.dof,
                   "p_value": chi2_sf(p.chi_square, p.dof as f64)})
        });
        vec![
            ("campaigns", Value::Array(campaigns)),
            ("disagreeing_campaigns", self.disagreeing.clone().into()),
            ("prior", prior.unwrap_or(Value::Null)),
        ]
    }

    /// The report's lines: one per campaign, then the prior.
    pub fn report(&self) -> String {
        let mut s = format!(
            "{} campaigns pooled, each with its own sensor offsets:\n",
            self.campaigns.len()
        );
        for c in &self.campaigns {
            let offsets = c
                .offsets
                .map_or("left out of the fit".to_string(), |(o, _)| {
                    format!(
                        "offsets phi {:.6} rad, theta {:.6} rad, s {:.4} mm",
                        o[0], o[1], o[2]
                    )
                });
            let agreement = c.agreement.map_or(String::new(), |a| {
                format!(
                    ", agreement chi2 {:.1} on {} (p = {:.2e})",
                    a.chi_square, a.dof, a.p_value
                )
            });
            let temperature = c
                .temperature_c
                .map_or(String::new(), |t| format!(", {t:.2} °C"));
            let poses = if c.in_fit {
                format!("{} poses", c.poses)
            } else {
                "its poses".to_string()
            };
            s.push_str(&format!(
                "  {}: {poses}{}, {offsets}{}{temperature}{agreement}{}\n",
                c.file,
                if c.rejected_lines.is_empty() {
                    String::new()
                } else {
                    format!(" (rejected lines {:?})", c.rejected_lines)
                },
                if c.in_fit {
                    format!(", chi2 {:.1} on {} readings", c.chi_square, c.readings)
                } else {
                    String::new()
                },
                if self.disagreeing.contains(&c.file) {
                    ": DISAGREES with the rest"
                } else {
                    ""
                }
            ));
        }
        if let Some(p) = &self.prior {
            s.push_str(&format!(
                "prior: the batch of {} ({} machines in its estimates): chi2 {:.1} on {} (p = {:.2e})\n",
                p.file,
                p.members,
                p.chi_square,
                p.dof,
                chi2_sf(p.chi_square, p.dof as f64)
            ));
        }
        s
    }

    /// The file records of the other campaigns and the prior for the
    /// machine file (the first campaign is its `data_file`).
    pub fn sources(&self) -> Result<Vec<ExternalSourceRecord>, Error> {
        let mut out = Vec::new();
        for c in self.campaigns.iter().skip(1) {
            let mut nuisance = serde_json::Map::new();
            if let Some((o, sd)) = c.offsets {
                for (name, v, s) in [
                    ("phi_rad", o[0], sd[0]),
                    ("theta_rad", o[1], sd[1]),
                    ("s_mm", o[2], sd[2]),
                ] {
                    nuisance.insert(format!("offset.{name}"), json!({"value": v, "std_dev": s}));
                }
            }
            out.push(ExternalSourceRecord {
                kind: "campaign".into(),
                sha256: crate::machine_file::sha256_file(Path::new(&c.file))?,
                file: c.file.clone(),
                records: c.poses,
                chi2_per_dof: (c.readings > 3).then(|| c.chi_square / (c.readings - 3) as f64),
                redundancy: c.readings.saturating_sub(3) as f64,
                checkable: c.in_fit,
                rejected_lines: c.rejected_lines.clone(),
                nuisance,
            });
        }
        if let Some(p) = &self.prior {
            out.push(ExternalSourceRecord {
                kind: "prior".into(),
                file: p.file.clone(),
                sha256: p.sha256.clone(),
                records: p.members,
                chi2_per_dof: Some(p.chi_square / p.dof.max(1) as f64),
                redundancy: p.dof as f64,
                checkable: true,
                rejected_lines: Vec::new(),
                nuisance: serde_json::Map::new(),
            });
        }
        Ok(out)
    }
}
