//! The diagnosis: is the geometric model adequate, and if not, why.
//!
//! 1. **Outliers.** The geometric model is fitted; a pose whose reading lies
//!    beyond the Bonferroni-corrected normal quantile of `3 n` readings (in
//!    noise units, against a robust scale of the residuals so that a
//!    systematic misfit is not mistaken for gross errors) is set aside, and
//!    the screen repeats on the refit. Flagged poses (at most 10 %) make the
//!    cause `outliers`; the rest of the analysis uses the clean poses.
//! 2. **Adequacy.** The chi-square of the weighted residuals against its
//!    degrees of freedom, and the correlation of the residuals with every
//!    available regressor.
//! 3. **Causes, by forward selection.** Every candidate effect whose data
//!    columns are present is fitted on top of the current model. It is
//!    selected only if (a) the nested likelihood-ratio test (the drop of
//!    chi-square, known noise) is significant at `alpha` divided by the
//!    number of candidates, (b) the BIC improves, and (c) the 5-fold
//!    cross-validated held-out residual RMS improves; the strongest (largest
//!    BIC gain) enters, and the search repeats.
//! 4. **Report.** Each cause with its parameters and standard deviations,
//!    the evidence, how far it had biased the geometric parameters, and the
//!    gain: held-out RMS and the platform displacement on the middle plane
//!    between the geometric-only and the extended calibration.

use rayon::prelude::*;
use serde::Serialize;
use serde_json::{Map, Value, json};
use tricept_data::{Dataset, MeasuredPose};
use tricept_ident::{
    GeometricModel, IdentError, Identification, IdentifyOptions, ReadingModel, identify,
    residuals_at, screen_gross_errors,
};
use tricept_kinematics::{Machine, SensorNoise, UpJoints};
use tricept_model::ParameterSet;
use tricept_plant::effects::EffectName;

use crate::model::{Candidate, ExtendedModel};
use tricept_ident::stats::chi2_sf;

/// Why a diagnosis could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DiagnoseError {
    /// The geometric identification itself failed.
    #[error(transparent)]
    Ident(#[from] IdentError),
    /// Too few poses for cross-validation.
    #[error("too few poses ({0}) for a diagnosis: at least 20 are needed")]
    TooFewPoses(usize),
}

/// Options of [`diagnose`].
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseOptions {
    /// Standard deviation of one logged reading `[phi, theta, s]`.
    pub sigma: [f64; 3],
    /// Family-wise significance level of the tests.
    pub alpha: f64,
    /// Folds of the cross-validation.
    pub folds: usize,
    /// Largest number of causes named.
    pub max_causes: usize,
    /// Lattice of the middle-plane comparison, mm.
    pub plane_spacing_mm: f64,
    /// Largest share of poses that may be called outliers.
    pub max_outlier_share: f64,
}

impl DiagnoseOptions {
    /// Defaults with the logged noise of `machine`'s sensors.
    pub fn for_machine(machine: &Machine) -> DiagnoseOptions {
        DiagnoseOptions {
            sigma: machine.sensors.logged_sigma(),
            alpha: 1e-3,
            folds: 5,
            max_causes: 3,
            plane_spacing_mm: 50.0,
            max_outlier_share: 0.1,
        }
    }
}

/// The statistical evidence for one candidate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Evidence {
    /// Drop of chi-square when the effect is added.
    pub delta_chi_square: f64,
    /// Identifiable parameters the effect adds (the test's degrees of freedom).
    pub dof: usize,
    /// Likelihood-ratio p-value.
    pub p_value: f64,
    /// The p-value it had to beat (alpha / candidates).
    pub threshold: f64,
    /// BIC improvement (`delta_chi_square - dof ln N`; positive favours the effect).
    pub delta_bic: f64,
    /// Held-out weighted residual RMS without the effect (noise = 1).
    pub holdout_rms_without: Option<f64>,
    /// Held-out weighted residual RMS with the effect.
    pub holdout_rms_with: Option<f64>,
    /// Whether every criterion passed.
    pub selected: bool,
}

/// An estimated parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Estimate {
    /// Name (unit in the name).
    pub name: String,
    /// Value.
    pub value: f64,
    /// Standard deviation (`None` when unidentifiable and held at zero).
    pub std_dev: Option<f64>,
}

/// A named cause.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cause {
    /// The effect, from the vocabulary.
    pub effect: EffectName,
    /// Its parameters in the final model.
    pub parameters: Vec<Estimate>,
    /// The evidence when it was selected.
    pub evidence: Evidence,
    /// Lines of the data file flagged (outliers only).
    pub rows: Vec<u64>,
}

/// A residual correlation with a regressor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Structure {
    /// The regressor.
    pub regressor: String,
    /// The reading channel (`phi`, `theta`, `s`).
    pub channel: &'static str,
    /// Pearson correlation of the weighted residual with the regressor.
    pub correlation: f64,
    /// Two-sided p-value (Fisher z).
    pub p_value: f64,
}

/// What the final model gains over the geometric one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gain {
    /// Held-out weighted residual RMS of the geometric model (noise = 1).
    pub holdout_rms_geometric: f64,
    /// Held-out weighted residual RMS of the final model.
    pub holdout_rms_extended: f64,
    /// Mean platform displacement on the middle plane between the
    /// geometric-only and the final calibration (commands of the former,
    /// positions predicted by both), mm.
    pub volumetric_mean_mm: f64,
    /// Largest such displacement, mm.
    pub volumetric_max_mm: f64,
    /// Mean displacement after removing the best-fit rigid translation
    /// (touch-off): most of the raw figure is often a translation along the
    /// weak leg-length direction that the sensors cannot see, mm.
    pub volumetric_touched_mean_mm: f64,
}

/// A residual plot: weighted residuals of a channel (or implied leg-length
/// residuals) against the regressor that exposes a cause.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResidualPlot {
    /// The cause it illustrates.
    pub effect: EffectName,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Points with the geometric model.
    pub before: Vec<(f64, f64)>,
    /// Points with the final model.
    pub after: Vec<(f64, f64)>,
}

/// The diagnosis of a data set.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Diagnosis {
    /// The geometric model alone explains the data.
    pub adequate: bool,
    /// Chi-square of the geometric fit (clean poses).
    pub chi_square: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// `P(chi2_dof > chi_square)`.
    pub chi_square_p_value: f64,
    /// RMS residual of the geometric fit `[phi arcsec, theta arcsec, s um]`.
    pub residual_rms_geometric: [f64; 3],
    /// Strongest residual correlations of the geometric fit.
    pub structure: Vec<Structure>,
    /// Named causes, strongest first.
    pub causes: Vec<Cause>,
    /// Every candidate tested at the first selection step.
    pub candidates: Vec<(EffectName, Evidence)>,
    /// When the data are not explained and no cause is found: what is seen.
    pub unexplained: Option<String>,
    /// Gain of the final model.
    pub gain: Gain,
    /// Geometric parameters of the geometric-only fit.
    pub geometric_only: Vec<Estimate>,
    /// Every parameter of the final model.
    pub extended: Vec<Estimate>,
    /// How much adding the causes moved each geometric parameter
    /// (final minus geometric-only), mm.
    pub geometric_bias: Vec<(String, f64)>,
    /// Residual plots of the named causes.
    pub plots: Vec<ResidualPlot>,
}

#[derive(Clone)]
struct Fit {
    model: ExtendedModel,
    id: Identification,
}

fn identify_options(options: &DiagnoseOptions) -> IdentifyOptions {
    IdentifyOptions::with_sigma(options.sigma)
}

fn fit(model: ExtendedModel, data: &Dataset, options: &DiagnoseOptions) -> Result<Fit, IdentError> {
    let id = identify(&model, data, &identify_options(options))?;
    Ok(Fit { model, id })
}

fn subset(data: &Dataset, keep: impl Fn(usize) -> bool) -> Dataset {
    Dataset {
        poses: data
            .poses
            .iter()
            .enumerate()
            .filter(|(j, _)| keep(*j))
            .map(|(_, p)| *p)
            .collect(),
        source: data.source.clone(),
    }
}

/// Weighted residuals of `poses` under a fitted model (offsets applied).
fn residuals_of(f: &Fit, poses: &[MeasuredPose], sigma: &[f64; 3]) -> Vec<Option<[f64; 3]>> {
    residuals_at(&f.model, &f.id.estimate, &f.id.offsets, poses, sigma)
}

/// K-fold cross-validated RMS of the weighted held-out residuals of
/// `model` on `data`, evaluated on the poses `evaluate` accepts.
fn holdout_rms(
    model: &ExtendedModel,
    data: &Dataset,
    options: &DiagnoseOptions,
    evaluate: &(dyn Fn(usize) -> bool + Sync),
) -> Option<f64> {
    let k = options.folds.max(2);
    let parts: Vec<Option<(f64, usize)>> = (0..k)
        .into_par_iter()
        .map(|fold| {
            let train = subset(data, |j| j % k != fold);
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

fn estimates(f: &Fit) -> Vec<Estimate> {
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
fn screen_outliers(
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

/// Regressors of every pose (name, value per pose).
fn regressors(nominal: &Machine, data: &Dataset) -> Vec<(String, Vec<f64>)> {
    let n = data.poses.len();
    let mut out: Vec<(String, Vec<f64>)> = Vec::new();
    let fk: Vec<Option<(UpJoints, nalgebra::Vector3<f64>)>> = data
        .poses
        .iter()
        .map(|p| {
            nominal
                .forward(&p.commands_mm)
                .ok()
                .map(|f| (f.up, f.position_mm))
        })
        .collect();
    type Solved = (UpJoints, nalgebra::Vector3<f64>);
    let get = |f: &dyn Fn(&Solved) -> f64| -> Vec<f64> {
        fk.iter().map(|v| v.as_ref().map_or(f64::NAN, f)).collect()
    };
    out.push(("x_mm".into(), get(&|v| v.1.x)));
    out.push(("y_mm".into(), get(&|v| v.1.y)));
    out.push(("z_mm".into(), get(&|v| v.1.z)));
    out.push(("phi_rad".into(), get(&|v| v.0.phi_rad)));
    out.push(("theta_rad".into(), get(&|v| v.0.theta_rad)));
    out.push(("q4_mm".into(), get(&|v| v.0.q4_mm)));
    for i in 0..3 {
        out.push((
            format!("q{}_mm", i + 1),
            data.poses.iter().map(|p| p.commands_mm[i]).collect(),
        ));
    }
    out.push(("pose_index".into(), (0..n).map(|j| j as f64).collect()));
    if data.poses.iter().all(|p| p.time_s.is_some()) {
        out.push((
            "time_s".into(),
            data.poses.iter().map(|p| p.time_s.unwrap_or(0.0)).collect(),
        ));
    }
    if data.poses.iter().all(|p| p.temp_c.is_some()) {
        out.push((
            "temp_c".into(),
            data.poses.iter().map(|p| p.temp_c.unwrap_or(0.0)).collect(),
        ));
    }
    if data.poses.iter().all(|p| p.approach.is_some()) {
        for i in 0..3 {
            out.push((
                format!("dir{}", i + 1),
                data.poses
                    .iter()
                    .map(|p| f64::from(p.approach.map_or(0, |a| a[i])))
                    .collect(),
            ));
        }
    }
    out
}

fn correlation(x: &[f64], y: &[f64]) -> Option<f64> {
    let pairs: Vec<(f64, f64)> = x
        .iter()
        .zip(y)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (*a, *b))
        .collect();
    let n = pairs.len() as f64;
    if n < 4.0 {
        return None;
    }
    let (mx, my) = pairs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (x, y) in &pairs {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx) * (x - mx);
        syy += (y - my) * (y - my);
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

fn structure(nominal: &Machine, data: &Dataset, residuals: &[Option<[f64; 3]>]) -> Vec<Structure> {
    let regs = regressors(nominal, data);
    let n = data.poses.len() as f64;
    let mut out = Vec::new();
    for (c, channel) in ["phi", "theta", "s"].iter().enumerate() {
        let y: Vec<f64> = residuals
            .iter()
            .map(|r| r.map_or(f64::NAN, |r| r[c]))
            .collect();
        for (name, x) in &regs {
            if let Some(r) = correlation(x, &y) {
                let z = r.clamp(-0.999_999, 0.999_999).atanh() * (n - 3.0).max(1.0).sqrt();
                out.push(Structure {
                    regressor: name.clone(),
                    channel,
                    correlation: r,
                    p_value: chi2_sf(z * z, 1.0),
                });
            }
        }
    }
    out.sort_by(|a, b| a.p_value.total_cmp(&b.p_value));
    out.truncate(6);
    out
}

/// The outcome of the selection of effects on clean data.
struct Selection {
    chosen: Vec<Candidate>,
    evidences: Vec<Evidence>,
    current: Fit,
    current_rms: Option<f64>,
    first_candidates: Vec<(EffectName, Evidence)>,
    geo: Fit,
}

/// Forward selection of effects (see the module docs), followed by swaps:
/// a selected effect is replaced by an unselected one when that lowers the
/// BIC of the whole model (forward selection alone can let an effect that
/// mimics two others in; `scale-gain` with `encoder-eccentricity` present
/// is first mistaken for `leg-lead`).
fn select(
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
    let bic = |f: &Fit| f.id.stats.chi_square + f.id.decision.rank as f64 * readings.ln();
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
                f.id.decision
                    .rank
                    .saturating_sub(current.id.decision.rank)
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
            first_candidates = tested.iter().map(|(c, e, _)| (c.0, e.clone())).collect();
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
                        .decision
                        .rank
                        .saturating_sub(w.id.decision.rank)
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

/// Diagnoses `data` taken on a machine whose nominal model is `nominal`.
///
/// # Example
/// ```no_run
/// use tricept_diagnose::diagnose::{diagnose, DiagnoseOptions};
/// use tricept_kinematics::Machine;
/// let m = Machine::paper();
/// let data = tricept_data::read_path("fixtures/data/diagnose-hidden-effect.csv".as_ref()).unwrap();
/// let d = diagnose(&m, &data, &DiagnoseOptions::for_machine(&m)).unwrap();
/// println!("adequate: {}, causes: {:?}", d.adequate, d.causes.iter().map(|c| c.effect).collect::<Vec<_>>());
/// ```
pub fn diagnose(
    nominal: &Machine,
    data: &Dataset,
    options: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let n = data.poses.len();
    if n < 20 {
        return Err(DiagnoseError::TooFewPoses(n));
    }
    let geometric = GeometricModel::new(nominal.clone(), ParameterSet::paper15());
    let base_model = ExtendedModel::new(geometric.clone(), &[]);

    // 1-3. Outliers, adequacy, causes; the outlier screen is repeated with
    // the selected effects, so that a systematic misfit the effects explain
    // is not taken for gross errors.
    let mut flagged = screen_outliers(&base_model, data, options)?;
    let mut selection;
    let mut rounds = 0;
    loop {
        rounds += 1;
        if (flagged.len() as f64) > options.max_outlier_share * n as f64 {
            flagged.clear();
        }
        let clean = subset(data, |j| !flagged.contains(&j));
        selection = select(&geometric, &clean, options)?;
        let model = ExtendedModel::new(geometric.clone(), &selection.chosen);
        let again = screen_outliers(&model, data, options)?;
        if again == flagged || rounds == 3 {
            break;
        }
        flagged = again;
    }
    let outliers = !flagged.is_empty();
    let is_clean = |j: usize| !flagged.contains(&j);
    let clean = subset(data, is_clean);
    let Selection {
        chosen,
        evidences,
        current,
        current_rms,
        first_candidates,
        geo,
    } = selection;

    // 2. Adequacy of the geometric model on the clean poses.
    let geo_fit = geo.clone();
    let geo_res = residuals_of(&geo, &clean.poses, &options.sigma);
    let chi_square = geo.id.stats.chi_square;
    let dof = geo.id.stats.dof;
    let chi_square_p_value = chi2_sf(chi_square, dof as f64);
    let a = SensorNoise::ARCSEC;
    let rms = geo.id.stats.rms;
    let residual_rms_geometric = [rms[0] / a, rms[1] / a, rms[2] * 1e3];
    let structure = structure(nominal, &clean, &geo_res);

    let mut causes = Vec::new();
    if outliers {
        let all = fit(current.model.clone(), data, options)?;
        let z_max = residuals_of(&current, &data.poses, &options.sigma)
            .iter()
            .flatten()
            .flat_map(|r| r.iter().map(|v| v.abs()))
            .fold(0.0, f64::max);
        let p_value = ((3 * n) as f64 * chi2_sf(z_max * z_max, 1.0)).min(1.0);
        let delta = all.id.stats.chi_square - current.id.stats.chi_square;
        causes.push(Cause {
            effect: EffectName::Outliers,
            parameters: vec![
                Estimate {
                    name: "flagged_poses".into(),
                    value: flagged.len() as f64,
                    std_dev: None,
                },
                Estimate {
                    name: "largest_residual_sigma".into(),
                    value: z_max,
                    std_dev: None,
                },
            ],
            evidence: Evidence {
                delta_chi_square: delta,
                dof: 3 * flagged.len(),
                p_value,
                threshold: options.alpha,
                delta_bic: delta - (3 * flagged.len()) as f64 * ((3 * n) as f64).ln(),
                holdout_rms_without: None,
                holdout_rms_with: None,
                selected: true,
            },
            rows: flagged.iter().map(|&j| data.poses[j].line).collect(),
        });
    }

    // 4. Report.
    let final_estimates = estimates(&current);
    let offsets = current.model.offsets();
    for ((c, ev), at) in chosen.iter().zip(&evidences).zip(&offsets) {
        causes.push(Cause {
            effect: c.0,
            parameters: final_estimates[*at..*at + c.params().len()].to_vec(),
            evidence: ev.clone(),
            rows: Vec::new(),
        });
    }
    // Strongest first (outliers first only when they are the strongest).
    causes.sort_by(|a, b| b.evidence.delta_bic.total_cmp(&a.evidence.delta_bic));

    let geometric_only = estimates(&geo_fit);
    let g = current.model.n_geometric();
    let geometric_bias = final_estimates[..g]
        .iter()
        .zip(&geometric_only)
        .map(|(f, o)| (f.name.clone(), f.value - o.value))
        .collect();

    // Gain: held-out RMS on the clean poses for both models; for outliers,
    // the geometric model is trained on all poses.
    let holdout_rms_geometric = if outliers {
        holdout_rms(&base_model, data, options, &is_clean)
    } else {
        holdout_rms(&base_model, &clean, options, &|_| true)
    }
    .unwrap_or(f64::NAN);
    let holdout_rms_extended = if chosen.is_empty() {
        holdout_rms(&current.model, &clean, options, &|_| true)
    } else {
        current_rms
    }
    .unwrap_or(f64::NAN);
    let displacement = volumetric_difference(nominal, &geo_fit, &current, options);
    let raw = displacement.stats();
    let touched = displacement.without_mean_translation().stats();

    let adequate = causes.is_empty() && chi_square_p_value > options.alpha;
    let unexplained = (!adequate && causes.is_empty()).then(|| {
        let s = structure.first();
        format!(
            "the geometric model leaves chi-square {chi_square:.1} for {dof} degrees of freedom (p = {chi_square_p_value:.2e}) and no candidate effect explains it{}",
            s.map_or(String::new(), |s| format!(
                "; strongest residual structure: {} residual vs {} (r = {:+.2}, p = {:.1e})",
                s.channel, s.regressor, s.correlation, s.p_value
            ))
        )
    });
    let plots = causes
        .iter()
        .filter_map(|c| residual_plot(c.effect, nominal, &clean, &geo_fit, &current, options))
        .collect();
    Ok(Diagnosis {
        adequate,
        chi_square,
        dof,
        chi_square_p_value,
        residual_rms_geometric,
        structure,
        causes,
        candidates: first_candidates,
        unexplained,
        gain: Gain {
            holdout_rms_geometric,
            holdout_rms_extended,
            volumetric_mean_mm: raw.mean_mm,
            volumetric_max_mm: raw.max_mm,
            volumetric_touched_mean_mm: touched.mean_mm,
        },
        geometric_only,
        extended: final_estimates,
        geometric_bias,
        plots,
    })
}

/// Displacement of the platform on the middle plane between the
/// geometric-only calibration and the final one: targets commanded through
/// the geometric fit's IK, positions predicted by the final model (leg
/// effects at the campaign's mean context).
fn volumetric_difference(
    nominal: &Machine,
    geo: &Fit,
    fin: &Fit,
    options: &DiagnoseOptions,
) -> tricept_model::ErrorMap {
    let targets = nominal
        .workspace
        .disc_grid(nominal.workspace.mid_plane_z_mm(), options.plane_spacing_mm);
    let m_geo = geo.model.machine_at(&geo.id.estimate);
    let m_fin = fin.model.machine_at(&fin.id.estimate);
    let predictor = fin.model.at(&fin.id.estimate);
    let k = fin.model.names().len();
    let mut jac = vec![0.0; 3 * k];
    let mut map = tricept_model::ErrorMap {
        targets_mm: Vec::new(),
        errors_mm: Vec::new(),
    };
    for r in &targets {
        let Ok(ik) = m_geo.inverse(r) else { continue };
        let pose = MeasuredPose {
            commands_mm: ik.legs_mm,
            approach: None,
            ..Default::default()
        };
        let mut seed = Some(ik.up);
        // The final model's reading prediction solves its UP joints (the
        // reading effects are sensor-side and do not move the platform).
        if predictor.predict(&pose, &mut seed, &mut jac).is_err() {
            continue;
        }
        let Some(up) = seed else { continue };
        map.targets_mm.push(*r);
        map.errors_mm.push(m_fin.up_limb.pose(&up).position_mm - r);
    }
    map
}

/// Residual plot of `effect`: leg-length residuals (`J1` times the joint
/// residuals, um) against the leg's regressor for leg effects; reading
/// residuals against the exposing joint value otherwise.
fn residual_plot(
    effect: EffectName,
    nominal: &Machine,
    data: &Dataset,
    geo: &Fit,
    fin: &Fit,
    options: &DiagnoseOptions,
) -> Option<ResidualPlot> {
    let series = |f: &Fit| -> Vec<(f64, f64)> {
        let res = residuals_of(f, &data.poses, &options.sigma);
        data.poses
            .iter()
            .zip(res)
            .filter_map(|(p, r)| {
                let r = r?;
                let joint = [0, 1, 2].map(|c| r[c] * options.sigma[c]);
                let fk = nominal.forward(&p.commands_mm).ok()?;
                let leg = nominal.legs_at(&fk.up).j1() * nalgebra::Vector3::from(joint);
                let x_y = match effect {
                    EffectName::LegLead => (p.commands_mm[0], leg[0] * 1e3),
                    EffectName::Backlash => (
                        f64::from(p.approach?[0]) + 0.02 * (p.line % 7) as f64,
                        leg[0] * 1e3,
                    ),
                    EffectName::Thermal => (p.temp_c?, leg.sum() / 3.0 * 1e3),
                    EffectName::Compliance => (
                        fk.up.theta_rad.hypot(fk.up.phi_rad).to_degrees(),
                        leg.sum() / 3.0 * 1e3,
                    ),
                    EffectName::ScaleGain => (fk.up.q4_mm, joint[2] * 1e3),
                    EffectName::EncoderEccentricity => {
                        (fk.up.phi_rad.to_degrees(), joint[0] / SensorNoise::ARCSEC)
                    }
                    EffectName::UjointAxes => {
                        (fk.up.theta_rad.to_degrees(), joint[0] / SensorNoise::ARCSEC)
                    }
                    EffectName::TubeTwist => (fk.up.q4_mm, leg[0] * 1e3),
                    EffectName::Outliers => {
                        (p.line as f64, r.iter().fold(0.0f64, |a, v| a.max(v.abs())))
                    }
                };
                Some(x_y)
            })
            .collect()
    };
    let (x_label, y_label) = match effect {
        EffectName::LegLead => ("leg 1 command (mm)", "leg 1 length residual (um)"),
        EffectName::Backlash => ("leg 1 approach direction", "leg 1 length residual (um)"),
        EffectName::Thermal => ("temperature (°C)", "mean leg length residual (um)"),
        EffectName::Compliance => ("tilt of the UP limb (deg)", "mean leg length residual (um)"),
        EffectName::ScaleGain => ("q4 (mm)", "scale residual (um)"),
        EffectName::EncoderEccentricity => ("phi (deg)", "phi residual (arcsec)"),
        EffectName::UjointAxes => ("theta (deg)", "phi residual (arcsec)"),
        EffectName::TubeTwist => ("q4 (mm)", "leg 1 length residual (um)"),
        EffectName::Outliers => ("line of the data file", "largest |residual| (sigma)"),
    };
    Some(ResidualPlot {
        effect,
        x_label: x_label.into(),
        y_label: y_label.into(),
        before: series(geo),
        after: series(fin),
    })
}

impl Diagnosis {
    /// JSON with the contract keys `adequate`, `causes` (each with
    /// `effect`, its parameter estimates and evidence) and `gain`
    /// (`holdout_rms_geometric`, `holdout_rms_extended`), and more.
    pub fn to_json(&self) -> Value {
        let params = |v: &[Estimate]| -> Value {
            Value::Object(
                v.iter()
                    .map(|e| {
                        (
                            e.name.clone(),
                            json!({"value": e.value, "std_dev": e.std_dev}),
                        )
                    })
                    .collect::<Map<String, Value>>(),
            )
        };
        json!({
            "adequate": self.adequate,
            "chi_square": self.chi_square,
            "dof": self.dof,
            "chi_square_p_value": self.chi_square_p_value,
            "residual_rms_geometric": {"phi_arcsec": self.residual_rms_geometric[0], "theta_arcsec": self.residual_rms_geometric[1], "s_um": self.residual_rms_geometric[2]},
            "causes": self.causes.iter().map(|c| json!({
                "effect": c.effect,
                "parameters": params(&c.parameters),
                "evidence": c.evidence,
                "rows": c.rows,
            })).collect::<Vec<_>>(),
            "unexplained": self.unexplained,
            "structure": self.structure,
            "candidates": self.candidates.iter().map(|(e, ev)| json!({"effect": e, "evidence": ev})).collect::<Vec<_>>(),
            "gain": self.gain,
            "geometric_only": params(&self.geometric_only),
            "extended": params(&self.extended),
            "geometric_bias_mm": Value::Object(self.geometric_bias.iter().map(|(n, v)| (n.clone(), Value::from(*v))).collect()),
        })
    }
}
