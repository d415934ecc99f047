//! Several campaigns of one machine, a batch's prior, or both
//! (`docs/fleet.md`): the internal fit of every pose with one set of sensor
//! offsets per campaign and the prior's rows, then each campaign's share
//! and whether it agrees with the rest (`tricept_fleet`); a campaign that
//! disagrees is named and left out of the estimate.

use std::path::Path;

use serde_json::Value;
use tricept_data::Dataset;
use tricept_engine::{IdentifyOptions, prior::Prior, verdict::ADEQUACY_ALPHA};
use tricept_fleet::{
    PriorFile, campaigns::agreements, campaigns::campaign_chi_squares, campaigns::pool,
};
use tricept_model::ParameterSet;
use tricept_numerics::stats::chi2_sf;

use super::checked::Checked;
use super::internal::{InternalFit, fit as internal_fit};
use super::pooling::{CampaignRow, Pooled, PriorUsed};
use crate::Setting;
use crate::error::Error;
use crate::inputs::LoadedMachine;

/// The batch's prior in `path`, for `loaded` and `set`: its machine must
/// be the one calibrated.
fn read_prior(
    path: &Path,
    loaded: &LoadedMachine,
    set: &ParameterSet,
) -> Result<(Prior, PriorFile), Error> {
    let name = path.display().to_string();
    let text =
        tricept_data::bounded::read_json_text(path).map_err(|e| Error::unreadable(&name, e))?;
    let file = PriorFile::from_json(&text, &name)
        .map_err(|e| Error::from_library(e).in_setting(Setting::Prior))?;
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
        return Err(Error::invalid_value(
            Setting::Prior,
            &name,
            format!(
                "the batch's machine is not `{}` (give the batch's nominal machine as the machine)",
                loaded.description().name
            ),
        ));
    }
    let prior = file
        .prior(set)
        .map_err(|e| Error::from_library(e).in_setting_value(Setting::Prior, &name))?;
    Ok((prior, file))
}

/// Calibrates from the campaigns `datasets` (at least one) and the prior at
/// `prior` (module docs).
pub(crate) fn fit(
    c: &Checked,
    datasets: &[Dataset],
    prior: Option<&Path>,
) -> Result<InternalFit, Error> {
    let (loaded, set) = (&c.loaded, &c.set);
    let m = loaded.machine();
    let (prior, prior_file) = match prior {
        Some(path) => {
            let (p, f) = read_prior(path, loaded, set)?;
            (Some(p), Some((path, f)))
        }
        None => (None, None),
    };
    let all = pool(datasets);
    let options = IdentifyOptions::for_machine(m);
    let mut used = all.clone();
    let mut fit = internal_fit(c, &used, prior.clone())?;
    let count = datasets.len();
    let mut tests = vec![None; count];
    let mut disagreeing = Vec::new();
    if count >= 2 {
        let kept = used.subset(|j| !fit.rejected.iter().any(|r| r.pose == j));
        let a = agreements(&fit.model, &kept, count, &options, ADEQUACY_ALPHA)
            .map_err(|e| Error::with_context("the campaigns' agreement", e))?;
        tests = a.tests;
        disagreeing = a.disagreeing;
        // Three or more campaigns: the ones that disagree leave the fit.
        if !disagreeing.is_empty() && disagreeing.len() < count {
            used = all.subset(|j| !disagreeing.contains(&all.poses[j].campaign));
            fit = internal_fit(c, &used, prior)?;
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
