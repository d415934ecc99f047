//! Selection of causes: every candidate effect fitted on top of the current
//! model, admitted by the likelihood-ratio test, the BIC and the
//! cross-validated held-out residual, then swaps that lower the BIC of the
//! whole model; the outlier screen with the diagnosis' options.

use rayon::prelude::*;
use tricept_data::{Dataset, MeasuredPose};
use tricept_ident::{
    GeometricModel, IdentError, Identification, IdentifyOptions, ReadingModel, identify,
    residuals_at, screen_gross_errors,
};
use tricept_numerics::stats::chi2_sf;

use crate::model::{Candidate, ExtendedModel};
use crate::report::{Estimate, Evidence, Tested};
use crate::run::DiagnoseOptions;

#[derive(Clone)]
pub(crate) struct Fit {
    pub(crate) model: ExtendedModel,
    pub(crate) id: Identification,
}

pub(crate) fn identify_options(options: &DiagnoseOptions) -> IdentifyOptions {
    IdentifyOptions::with_sigma(options.sigma)
}

pub(crate) fn fit(
    model: ExtendedModel,
    data: &Dataset,
    options: &DiagnoseOptions,
) -> Result<Fit, IdentError> {
    let id = identify(&model, data, &identify_options(options))?;
    Ok(Fit { model, id })
}

/// Weighted residuals of `poses` under a fitted model (offsets applied).
pub(crate) fn residuals_of(
    f: &Fit,
    poses: &[MeasuredPose],
    sigma: &[f64; 3],
) -> Vec<Option<[f64; 3]>> {
    // A fit's estimate always has its model's length.
    residuals_at(&f.model, &f.id.estimate, &f.id.offsets, poses, sigma)
        .unwrap_or_else(|_| vec![None; poses.len()])
}

/// K-fold cross-validated RMS of the weighted held-out residuals of
/// `model` on `data`, evaluated on the poses `evaluate` accepts.
pub(crate) fn holdout_rms(
    model: &ExtendedModel,
    data: &Dataset,
    options: &DiagnoseOptions,
    evaluate: &(dyn Fn(usize) -> bool + Sync),
) -> Option<f64> {
    let k = options.folds.max(2);
    let parts: Vec<Option<(f64, usize)>> = (0..k)
        .into_par_iter()
        .map(|fold| {
            let train = data.subset(|j| j % k != fold);
            let f = fit(model.clone(), &train, options).ok()?;
            let test: Vec<(usize, MeasuredPose)> = data
                .poses
                .iter()
                .enumerate()
                .filter(|(j, _)| j % k == fold && evaluate(*j))
                .map(|(j, p)| (j, *p))
                .collect();
            let poses: Vec<MeasuredPose> = test.iter().map(|(_, p)| *p).collect();
            let res = residuals_of(&f, &poses, &options.sigma);
            let mut sum = 0.0;
            let mut n = 0;
            for r in res.into_iter().flatten() {
                sum += r.iter().map(|v| v * v).sum::<f64>();
                n += 3;
            }
            Some((sum, n))
        })
        .collect();
    let (mut sum, mut n) = (0.0, 0);
    for (s, c) in parts.into_iter().flatten() {
        sum += s;
        n += c;
    }
    (n > 0).then(|| (sum / n as f64).sqrt())
}

pub(crate) fn estimates(f: &Fit) -> Vec<Estimate> {
    f.model
        .names()
        .iter()
        .zip(&f.id.estimate)
        .zip(&f.id.std_dev)
        .map(|((n, v), s)| Estimate {
            name: n.clone(),
            value: *v,
            std_dev: *s,
        })
        .collect()
}

/// The outlier screen of `tricept_ident::robust` with the diagnosis'
/// options; the indices of the flagged poses.
pub(crate) fn screen_outliers(
    model: &ExtendedModel,
    data: &Dataset,
    options: &DiagnoseOptions,
) -> Result<Vec<usize>, IdentError> {
    Ok(screen_gross_errors(
        model,
        data,
        &identify_options(options),
        options.alpha,
        options.max_outlier_share,
    )?
    .into_iter()
    .map(|r| r.pose)
    .collect())
}

/// The outcome of the selection of effects on clean data.
pub(crate) struct Selection {
    pub(crate) chosen: Vec<Candidate>,
    pub(crate) evidences: Vec<Evidence>,
    pub(crate) current: Fit,
    pub(crate) current_rms: Option<f64>,
    pub(crate) first_candidates: Vec<Tested>,
    pub(crate) geo: Fit,
}

/// Forward selection of effects (see the module docs), followed by swaps:
/// a selected effect is replaced by an unselected one when that lowers the
/// BIC of the whole model (forward selection alone can let an effect that
/// mimics two others in; `scale-gain` with `encoder-eccentricity` present
/// is first mistaken for `leg-lead`).
pub(crate) fn select(
    geometric: &GeometricModel,
    clean: &Dataset,
    options: &DiagnoseOptions,
) -> Result<Selection, IdentError> {
    let base_model = ExtendedModel::new(geometric.clone(), &[]);
    let geo = fit(base_model, clean, options)?;
    let available: Vec<Candidate> = Candidate::ALL
        .iter()
        .copied()
        .filter(|c| c.available(clean))
        .collect();
    let threshold = options.alpha / available.len().max(1) as f64;
    let readings = (3 * clean.poses.len()) as f64;
    let bic = |f: &Fit| f.id.stats.chi_square + f.id.design().rank() as f64 * readings.ln();
    let mut current = geo.clone();
    let mut current_rms: Option<f64> = None;
    let mut first_candidates = Vec::new();
    let mut chosen: Vec<Candidate> = Vec::new();
    let mut evidences: Vec<Evidence> = Vec::new();
    for step in 0..options.max_causes {
        let remaining: Vec<Candidate> = available
            .iter()
            .copied()
            .filter(|c| !chosen.contains(c))
            .collect();
        let trials: Vec<(Candidate, Option<Fit>)> = remaining
            .par_iter()
            .map(|c| {
                let mut effects = chosen.clone();
                effects.push(*c);
                let m = ExtendedModel::new(geometric.clone(), &effects);
                (*c, fit(m, clean, options).ok())
            })
            .collect();
        let mut tested: Vec<(Candidate, Evidence, Option<Fit>)> = Vec::new();
        for (c, f) in trials {
            let Some(f) = f else { continue };
            let delta = current.id.stats.chi_square - f.id.stats.chi_square;
            let k =
                f.id.design()
                    .rank()
                    .saturating_sub(current.id.design().rank())
                    .max(1);
            let p = chi2_sf(delta.max(0.0), k as f64);
            let delta_bic = delta - k as f64 * readings.ln();
            tested.push((
                c,
                Evidence {
                    delta_chi_square: delta,
                    dof: k,
                    p_value: p,
                    threshold,
                    delta_bic,
                    holdout_rms_without: None,
                    holdout_rms_with: None,
                    selected: false,
                },
                Some(f),
            ));
        }
        // Strongest first by BIC: among effects that explain the same
        // signature (a gain of the scale and an equal lead of the three legs
        // both scale the machine), the one with fewer parameters wins.
        tested.sort_by(|a, b| b.1.delta_bic.total_cmp(&a.1.delta_bic));
        // Cross-validate the candidates that pass the likelihood-ratio test
        // and the BIC, strongest first, and take the first that also
        // predicts held-out poses better.
        let mut winner: Option<(Candidate, Evidence, Fit)> = None;
        for (c, ev, f) in tested.iter_mut() {
            if ev.p_value >= threshold || ev.delta_bic <= 0.0 || winner.is_some() {
                continue;
            }
            if current_rms.is_none() {
                current_rms = holdout_rms(&current.model, clean, options, &|_| true);
            }
            let Some(f) = f.take() else { continue };
            let with = holdout_rms(&f.model, clean, options, &|_| true);
            ev.holdout_rms_without = current_rms;
            ev.holdout_rms_with = with;
            if let (Some(a), Some(b)) = (current_rms, with)
                && b < a
            {
                ev.selected = true;
                winner = Some((*c, ev.clone(), f));
                current_rms = with;
            }
        }
        if step == 0 {
            first_candidates = tested
                .iter()
                .map(|(c, e, _)| Tested {
                    effect: c.0,
                    evidence: e.clone(),
                })
                .collect();
        }
        match winner {
            Some((c, ev, f)) => {
                chosen.push(c);
                evidences.push(ev);
                current = f;
            }
            None => break,
        }
    }
    // Swaps.
    let mut improved = !chosen.is_empty();
    while improved {
        improved = false;
        let options_swap: Vec<(usize, Candidate)> = (0..chosen.len())
            .flat_map(|slot| {
                available
                    .iter()
                    .copied()
                    .filter(|c| !chosen.contains(c))
                    .map(move |c| (slot, c))
            })
            .collect();
        let best = options_swap
            .par_iter()
            .filter_map(|&(slot, c)| {
                let mut effects = chosen.clone();
                effects[slot] = c;
                let f = fit(
                    ExtendedModel::new(geometric.clone(), &effects),
                    clean,
                    options,
                )
                .ok()?;
                Some((bic(&f), slot, c, f))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((value, slot, c, f)) = best
            && value < bic(&current) - 1e-6
        {
            chosen[slot] = c;
            current = f;
            current_rms = holdout_rms(&current.model, clean, options, &|_| true);
            improved = true;
        }
    }
    // The evidence of each cause is its contribution to the final model:
    // the final model against the final model without it.
    let evidences: Vec<Evidence> = if chosen.len() == evidences.len() && chosen.len() > 1 {
        (0..chosen.len())
            .into_par_iter()
            .map(|slot| {
                let effects: Vec<Candidate> = chosen
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| *i != slot)
                    .map(|(_, c)| *c)
                    .collect();
                let model = ExtendedModel::new(geometric.clone(), &effects);
                let without = fit(model.clone(), clean, options).ok();
                let mut ev = evidences[slot].clone();
                if let Some(w) = without {
                    let delta = w.id.stats.chi_square - current.id.stats.chi_square;
                    let k = current
                        .id
                        .design()
                        .rank()
                        .saturating_sub(w.id.design().rank())
                        .max(1);
                    ev.delta_chi_square = delta;
                    ev.dof = k;
                    ev.p_value = chi2_sf(delta.max(0.0), k as f64);
                    ev.delta_bic = delta - k as f64 * readings.ln();
                    ev.holdout_rms_without = holdout_rms(&model, clean, options, &|_| true);
                    ev.holdout_rms_with = current_rms;
                }
                ev
            })
            .collect()
    } else {
        evidences
    };
    Ok(Selection {
        chosen,
        evidences,
        current,
        current_rms,
        first_candidates,
        geo,
    })
}
